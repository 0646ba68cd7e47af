// PNG images of renders and screenshots: 8-bit RGB, no interlace, each row
// filtered with "none" and the whole compressed with zlib (the PNG
// specification, ISO/IEC 15948, §§ 5, 10, 11). The same pixels always give
// the same bytes: no time stamp or other varying chunk is written.
#ifndef VMHAPTICS_VIZ_PNG_H_
#define VMHAPTICS_VIZ_PNG_H_

#include <cstdint>
#include <string>
#include <vector>

namespace vmh::viz {

// The PNG file for width x height pixels, `rgb` holding 3 bytes per pixel,
// rows from the top. Throws std::invalid_argument on a size that does not
// match, std::runtime_error if zlib fails.
std::string encode_png(int width_px, int height_px,
                       const std::vector<std::uint8_t>& rgb);

// OpenGL reads rows from the bottom (mjr_readPixels): flips them in place.
void flip_rows(int width_px, int height_px, std::vector<std::uint8_t>* rgb);

// encode_png written atomically (output/output_file.h) to `path`.
void write_png(const std::string& path, int width_px, int height_px,
               const std::vector<std::uint8_t>& rgb);

}  // namespace vmh::viz

#endif  // VMHAPTICS_VIZ_PNG_H_

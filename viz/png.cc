#include "viz/png.h"

#include <zlib.h>

#include <stdexcept>

#include "output/output_file.h"

namespace vmh::viz {
namespace {

void put_u32(std::string* s, std::uint32_t v) {
  s->push_back(static_cast<char>((v >> 24) & 0xff));
  s->push_back(static_cast<char>((v >> 16) & 0xff));
  s->push_back(static_cast<char>((v >> 8) & 0xff));
  s->push_back(static_cast<char>(v & 0xff));
}

// a chunk: length, type, data, CRC-32 of type and data
void put_chunk(std::string* png, const char type[4], const std::string& data) {
  put_u32(png, static_cast<std::uint32_t>(data.size()));
  const std::string body = std::string(type, 4) + data;
  png->append(body);
  const uLong crc =
      crc32(crc32(0L, Z_NULL, 0),
            reinterpret_cast<const Bytef*>(body.data()),
            static_cast<uInt>(body.size()));
  put_u32(png, static_cast<std::uint32_t>(crc));
}

}  // namespace

std::string encode_png(int width_px, int height_px,
                       const std::vector<std::uint8_t>& rgb) {
  if (width_px <= 0 || height_px <= 0) {
    throw std::invalid_argument("png: size " + std::to_string(width_px) +
                                " x " + std::to_string(height_px) +
                                " px is empty");
  }
  const std::size_t row = 3u * static_cast<std::size_t>(width_px);
  if (rgb.size() != row * static_cast<std::size_t>(height_px)) {
    throw std::invalid_argument(
        "png: " + std::to_string(rgb.size()) + " bytes for " +
        std::to_string(width_px) + " x " + std::to_string(height_px) +
        " RGB pixels");
  }
  // each scanline starts with its filter type, 0 (none)
  std::string raw;
  raw.reserve((row + 1) * static_cast<std::size_t>(height_px));
  for (int y = 0; y < height_px; ++y) {
    raw.push_back('\0');
    raw.append(reinterpret_cast<const char*>(rgb.data()) + row * y, row);
  }
  uLongf zlen = compressBound(static_cast<uLong>(raw.size()));
  std::string z(zlen, '\0');
  if (compress2(reinterpret_cast<Bytef*>(z.data()), &zlen,
                reinterpret_cast<const Bytef*>(raw.data()),
                static_cast<uLong>(raw.size()), 6) != Z_OK) {
    throw std::runtime_error("png: zlib could not compress the image");
  }
  z.resize(zlen);

  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  put_u32(&ihdr, static_cast<std::uint32_t>(width_px));
  put_u32(&ihdr, static_cast<std::uint32_t>(height_px));
  ihdr.push_back(8);  // bit depth
  ihdr.push_back(2);  // colour type: RGB
  ihdr.push_back(0);  // compression: deflate
  ihdr.push_back(0);  // filter method 0
  ihdr.push_back(0);  // no interlace
  put_chunk(&png, "IHDR", ihdr);
  put_chunk(&png, "IDAT", z);
  put_chunk(&png, "IEND", std::string());
  return png;
}

void flip_rows(int width_px, int height_px, std::vector<std::uint8_t>* rgb) {
  const std::size_t row = 3u * static_cast<std::size_t>(width_px);
  for (int y = 0; y < height_px / 2; ++y) {
    std::swap_ranges(rgb->begin() + static_cast<long>(row * y),
                     rgb->begin() + static_cast<long>(row * (y + 1)),
                     rgb->begin() +
                         static_cast<long>(row * (height_px - 1 - y)));
  }
}

void write_png(const std::string& path, int width_px, int height_px,
               const std::vector<std::uint8_t>& rgb) {
  output::write_file_atomically(path, encode_png(width_px, height_px, rgb));
}

}  // namespace vmh::viz

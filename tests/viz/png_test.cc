// viz/png: the file read back by an independent route: the chunk layout of
// the PNG specification, each chunk's CRC, and zlib's inflate of the data.
#include "viz/png.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <stdexcept>

namespace vmh::viz {
namespace {

std::uint32_t u32(const std::string& s, std::size_t at) {
  return (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at])) << 24) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 1])) << 16) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 2])) << 8) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[at + 3]));
}

TEST(Png, ChunksAndPixelsReadBack) {
  const int w = 5, h = 3;
  std::vector<std::uint8_t> rgb(3 * w * h);
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    rgb[i] = static_cast<std::uint8_t>(i * 7 + 1);
  }
  const std::string png = encode_png(w, h, rgb);
  ASSERT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // IHDR: 13 bytes, width, height, depth 8, colour type 2
  EXPECT_EQ(u32(png, 8), 13u);
  EXPECT_EQ(png.substr(12, 4), "IHDR");
  EXPECT_EQ(u32(png, 16), 5u);
  EXPECT_EQ(u32(png, 20), 3u);
  EXPECT_EQ(png[24], 8);
  EXPECT_EQ(png[25], 2);
  // every chunk's CRC over its type and data
  std::size_t at = 8;
  std::string idat;
  std::vector<std::string> types;
  while (at < png.size()) {
    const std::uint32_t len = u32(png, at);
    const std::string type = png.substr(at + 4, 4);
    types.push_back(type);
    const std::string body = png.substr(at + 4, 4 + len);
    const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(body.data()),
                            static_cast<uInt>(body.size()));
    EXPECT_EQ(u32(png, at + 8 + len), static_cast<std::uint32_t>(crc)) << type;
    if (type == "IDAT") idat += png.substr(at + 8, len);
    at += 12 + len;
  }
  EXPECT_EQ(at, png.size());
  ASSERT_EQ(types, (std::vector<std::string>{"IHDR", "IDAT", "IEND"}));
  // inflate: each row is a filter byte (0) and the row's pixels
  std::string raw((3 * w + 1) * h, '\0');
  uLongf raw_len = static_cast<uLongf>(raw.size());
  ASSERT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &raw_len,
                       reinterpret_cast<const Bytef*>(idat.data()),
                       static_cast<uLong>(idat.size())),
            Z_OK);
  ASSERT_EQ(raw_len, raw.size());
  for (int y = 0; y < h; ++y) {
    EXPECT_EQ(raw[static_cast<std::size_t>(y * (3 * w + 1))], '\0');
    for (int i = 0; i < 3 * w; ++i) {
      EXPECT_EQ(static_cast<std::uint8_t>(raw[y * (3 * w + 1) + 1 + i]),
                rgb[y * 3 * w + i]);
    }
  }
  // the same pixels, the same bytes
  EXPECT_EQ(encode_png(w, h, rgb), png);
}

TEST(Png, FlipRowsReversesRowOrder) {
  std::vector<std::uint8_t> rgb = {1, 2, 3, 4, 5, 6, 7, 8, 9};  // 1 x 3
  flip_rows(1, 3, &rgb);
  EXPECT_EQ(rgb, (std::vector<std::uint8_t>{7, 8, 9, 4, 5, 6, 1, 2, 3}));
}

TEST(Png, WrongSizeIsNamed) {
  try {
    encode_png(4, 4, std::vector<std::uint8_t>(10));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("10 bytes for 4 x 4"),
              std::string::npos);
  }
  EXPECT_THROW(encode_png(0, 4, {}), std::invalid_argument);
}

}  // namespace
}  // namespace vmh::viz

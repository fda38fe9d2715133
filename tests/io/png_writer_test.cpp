// PNG writer: signature, size, pixel values (decoded with stb_image), no partial file.
#include "io/io_test_util.h"
#include "io/writer.h"

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_PNG
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

using pointrast::InputError;
using pointrast::packRgba;
using namespace pointrast::io;

namespace {

TEST(PngWriter, WritesRgbWithTopRowFirst) {
  iotest::TempDir dir;
  const uint32_t w = 5, h = 3;
  std::vector<uint32_t> pixels(w * h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      pixels[y * w + x] = packRgba(10 * x, 100 + y, 7, y == 0 ? 0 : 255);
  auto path = dir / "img.png";
  writePng(path, w, h, pixels.data());
  EXPECT_FALSE(std::filesystem::exists(dir / "img.png.partial"));
  auto bytes = iotest::readBytes(path);
  const uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  ASSERT_GT(bytes.size(), 33u);
  EXPECT_EQ(std::memcmp(bytes.data(), signature, 8), 0);
  // IHDR: width and height big-endian at 16 and 20, bit depth 8, color type 2 (RGB).
  auto be32 = [&](size_t at) {
    return uint32_t(bytes[at]) << 24 | bytes[at + 1] << 16 | bytes[at + 2] << 8 | bytes[at + 3];
  };
  EXPECT_EQ(be32(16), w);
  EXPECT_EQ(be32(20), h);
  EXPECT_EQ(bytes[24], 8);
  EXPECT_EQ(bytes[25], 2);

  int dw = 0, dh = 0, comp = 0;
  uint8_t* decoded = stbi_load_from_memory(bytes.data(), static_cast<int>(bytes.size()), &dw, &dh, &comp, 3);
  ASSERT_NE(decoded, nullptr);
  EXPECT_EQ(dw, int(w));
  EXPECT_EQ(dh, int(h));
  EXPECT_EQ(comp, 3);
  for (uint32_t i = 0; i < w * h; ++i) {
    EXPECT_EQ(decoded[3 * i], iotest::channel(pixels[i], 0));
    EXPECT_EQ(decoded[3 * i + 1], iotest::channel(pixels[i], 1));
    EXPECT_EQ(decoded[3 * i + 2], iotest::channel(pixels[i], 2));
  }
  stbi_image_free(decoded);
}

TEST(PngWriter, FailuresLeaveNothingBehind) {
  iotest::TempDir dir;
  uint32_t pixel = packRgba(1, 2, 3);
  EXPECT_THROW(writePng(dir / "missing" / "a.png", 1, 1, &pixel), InputError);
  EXPECT_THROW(writePng(dir / "zero.png", 0, 1, &pixel), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "zero.png"));
  std::filesystem::create_directories(dir / "taken.png" / "child");
  EXPECT_THROW(writePng(dir / "taken.png", 1, 1, &pixel), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "taken.png.partial"));
}

} // namespace

#include "image_compare.h"

#include <cmath>
#include <cstdlib>

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_image.h>
#pragma GCC diagnostic pop

namespace pointrast::test {

namespace {

bool loadPng(const std::string& file, std::vector<uint32_t>& rgba, uint32_t& width, uint32_t& height) {
  int w = 0, h = 0, channels = 0;
  unsigned char* data = stbi_load(file.c_str(), &w, &h, &channels, 4);
  if (!data) return false;
  rgba.resize(size_t(w) * size_t(h));
  for (size_t i = 0; i < rgba.size(); ++i)
    rgba[i] = uint32_t(data[4 * i]) | uint32_t(data[4 * i + 1]) << 8 | uint32_t(data[4 * i + 2]) << 16 |
              0xFF000000u;
  stbi_image_free(data);
  width = uint32_t(w);
  height = uint32_t(h);
  return true;
}

ImageDifference difference(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  ImageDifference d;
  d.sameSize = a.size() == b.size() && !a.empty();
  if (!d.sameSize) return d;
  double squares = 0, absolute = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      double e = double((a[i] >> (8 * c)) & 0xFF) - double((b[i] >> (8 * c)) & 0xFF);
      squares += e * e;
      absolute += std::abs(e);
    }
  double n = double(a.size()) * 3;
  d.meanAbs = absolute / n;
  d.psnr = squares == 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / (squares / n));
  return d;
}

} // namespace

ImageDifference compareWithPng(const std::vector<uint32_t>& rgba, uint32_t width, uint32_t height,
                               const std::string& png) {
  std::vector<uint32_t> other;
  uint32_t w = 0, h = 0;
  if (!loadPng(png, other, w, h) || w != width || h != height) return {};
  return difference(rgba, other);
}

ImageDifference comparePngs(const std::string& a, const std::string& b) {
  std::vector<uint32_t> image;
  uint32_t w = 0, h = 0;
  if (!loadPng(a, image, w, h)) return {};
  return compareWithPng(image, w, h, b);
}

bool readPng(const std::string& file, std::vector<uint32_t>& rgba, uint32_t& width, uint32_t& height) {
  return loadPng(file, rgba, width, height);
}

} // namespace pointrast::test

// Comparing a streamed (JPEG) frame with `render`'s PNG of the same camera.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pointrast::test {

// The tolerance of a full frame at rest (JPEG quality 90, 4:4:4) against the lossless render, measured on
// autzen_trim (single-pixel points on black are JPEG's worst case): PSNR over RGB at least this, and the
// mean absolute difference per channel at most this (of 255).
constexpr double kJpegPsnr = 30.0;
constexpr double kJpegMeanAbs = 3.0;

struct ImageDifference {
  bool sameSize = false;
  double psnr = 0;    // dB over the RGB channels; 99 when identical
  double meanAbs = 0; // mean absolute difference per channel
};

// RGBA8 (r in the low byte) against a PNG file.
ImageDifference compareWithPng(const std::vector<uint32_t>& rgba, uint32_t width, uint32_t height,
                               const std::string& png);
// Two PNG files.
ImageDifference comparePngs(const std::string& a, const std::string& b);
// A PNG file decoded as RGBA8 (r in the low byte, alpha 255); false when it does not decode.
bool readPng(const std::string& file, std::vector<uint32_t>& rgba, uint32_t& width, uint32_t& height);

} // namespace pointrast::test

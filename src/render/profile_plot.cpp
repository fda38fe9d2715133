// Profile side views (profile_plot.h): points splatted into a z-buffer, then the frame, "nice" ticks
// (steps of 1, 2 or 5 times a power of ten) and their labels in a small 5 x 7 font of the characters the
// labels use (digits, '.', '-' and the letters of the axis titles).
#include "render/profile_plot.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>

#include "cloud/cloud.h"

namespace pointrast {

namespace {

const uint32_t kBackground = packRgba(250, 250, 250);
const uint32_t kPlotBackground = packRgba(32, 34, 40);
const uint32_t kInk = packRgba(30, 30, 30);
const uint32_t kGrid = packRgba(70, 74, 84);

struct Image {
  uint32_t width, height;
  std::vector<uint32_t> pixels;
  void set(int x, int y, uint32_t c) {
    if (x >= 0 && y >= 0 && x < int(width) && y < int(height)) pixels[size_t(y) * width + size_t(x)] = c;
  }
  void fill(int x0, int y0, int x1, int y1, uint32_t c) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x)
        set(x, y, c);
  }
};

constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kGlyphCellWidth = 6, kGlyphCellHeight = 9;

// Rows top first; bit 4 is the leftmost pixel. Characters without a glyph draw as blanks.
struct Glyph {
  char c;
  uint8_t rows[kGlyphHeight];
};
constexpr Glyph kGlyphs[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'a', {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}}, {'c', {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}},
    {'d', {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}}, {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {'g', {0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E}}, {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'i', {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}}, {'l', {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}}, {'o', {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}},
    {'s', {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}}, {'t', {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}},
    {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04}},
};

int textWidth(const std::string& text, int scale) {
  return int(text.size()) * kGlyphCellWidth * scale;
}

void drawText(Image& img, int x, int y, const std::string& text, uint32_t color, int scale) {
  int cx = x;
  for (char c : text) {
    const Glyph* g = nullptr;
    for (const Glyph& candidate : kGlyphs)
      if (candidate.c == c) g = &candidate;
    for (int gy = 0; g && gy < kGlyphHeight; ++gy)
      for (int gx = 0; gx < kGlyphWidth; ++gx)
        if ((g->rows[gy] >> (kGlyphWidth - 1 - gx)) & 1)
          img.fill(cx + gx * scale, y + (gy + 1) * scale, cx + (gx + 1) * scale, y + (gy + 2) * scale, color);
    cx += kGlyphCellWidth * scale;
  }
}

// A tick step of 1, 2 or 5 x 10^k giving about `count` ticks over `range`.
double niceStep(double range, int count) {
  const double raw = range / std::max(count, 1);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (m * power >= raw) return m * power;
  return 10 * power;
}

std::string tickLabel(double value, double step) {
  const int decimals = step >= 1 ? 0 : int(std::ceil(-std::log10(step) - 1e-9));
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, std::abs(value) < step * 1e-6 ? 0.0 : value);
  return text;
}

} // namespace

std::vector<uint32_t> plotProfile(const std::vector<ProfileSample>& samples, const ProfilePlot& plot) {
  assert(plot.width >= 200 && plot.height >= 120 && plot.length > 0);
  Image img{plot.width, plot.height, std::vector<uint32_t>(size_t(plot.width) * plot.height, kBackground)};
  const int scale = plot.width >= 900 ? 2 : 1;
  const int cellW = kGlyphCellWidth * scale, cellH = kGlyphCellHeight * scale;

  double zMin = std::numeric_limits<double>::infinity(), zMax = -zMin;
  for (const ProfileSample& s : samples) {
    zMin = std::min(zMin, s.elevation);
    zMax = std::max(zMax, s.elevation);
  }
  if (!(zMin <= zMax)) zMin = 0, zMax = 1;
  const double pad = std::max(0.05 * (zMax - zMin), 0.5);
  zMin -= pad;
  zMax += pad;
  const double yStep = niceStep(zMax - zMin, 5), xStep = niceStep(plot.length, 8);
  int labelWidth = 0;
  for (double v = std::ceil(zMin / yStep) * yStep; v <= zMax; v += yStep)
    labelWidth = std::max(labelWidth, textWidth(tickLabel(v, yStep), scale));

  // Plot area [left, right) x [top, bottom).
  const int left = labelWidth + cellW * 3, right = int(plot.width) - cellW * 2;
  const int top = cellH * 2, bottom = int(plot.height) - cellH * 3;
  const double sx = (right - left) / plot.length, sy = (bottom - top) / (zMax - zMin);
  auto px = [&](double d) { return left + int(std::floor(d * sx)); };
  auto py = [&](double z) { return bottom - 1 - int(std::floor((z - zMin) * sy)); };
  img.fill(left, top, right, bottom, kPlotBackground);

  // Grid lines under the points.
  for (double v = std::ceil(zMin / yStep) * yStep; v <= zMax; v += yStep)
    img.fill(left, py(v), right, py(v) + 1, kGrid);
  for (double d = 0; d <= plot.length + 1e-9 * plot.length; d += xStep)
    img.fill(px(d), top, px(d) + 1, bottom, kGrid);

  // Points: the nearest wins every pixel it covers.
  std::vector<float> depth(size_t(plot.width) * plot.height, std::numeric_limits<float>::infinity());
  for (const ProfileSample& s : samples) {
    const int x0 = px(s.distance) - plot.pointSize / 2, y0 = py(s.elevation) - plot.pointSize / 2;
    for (int y = std::max(y0, top); y < std::min(y0 + plot.pointSize, bottom); ++y)
      for (int x = std::max(x0, left); x < std::min(x0 + plot.pointSize, right); ++x) {
        const size_t i = size_t(y) * plot.width + size_t(x);
        if (float(s.depth) < depth[i]) {
          depth[i] = float(s.depth);
          img.pixels[i] = s.color;
        }
      }
  }

  // Frame, ticks and labels.
  img.fill(left - 1, top - 1, right + 1, top, kInk);
  img.fill(left - 1, bottom, right + 1, bottom + 1, kInk);
  img.fill(left - 1, top - 1, left, bottom + 1, kInk);
  img.fill(right, top - 1, right + 1, bottom + 1, kInk);
  for (double v = std::ceil(zMin / yStep) * yStep; v <= zMax; v += yStep) {
    const int y = py(v);
    img.fill(left - cellW / 2, y, left, y + 1, kInk);
    const std::string label = tickLabel(v, yStep);
    drawText(img, left - cellW / 2 - scale * 2 - textWidth(label, scale), y - cellH / 2, label, kInk, scale);
  }
  for (double d = 0; d <= plot.length + 1e-9 * plot.length; d += xStep) {
    const int x = px(d);
    img.fill(x, bottom, x + 1, bottom + cellW / 2, kInk);
    const std::string label = tickLabel(d, xStep);
    drawText(img, x - textWidth(label, scale) / 2, bottom + cellW / 2, label, kInk, scale);
  }
  const std::string xTitle = "distance along the line";
  drawText(img, (left + right - textWidth(xTitle, scale)) / 2, bottom + cellW / 2 + cellH, xTitle, kInk,
           scale);
  drawText(img, cellW / 2, top - cellH - scale * 2, "elevation", kInk, scale);
  return img.pixels;
}

} // namespace pointrast

// The annotation overlay on the CPU: markers land on the pixel the camera contract projects a point to,
// lines are hidden where the frame's points are closer, labels draw the bitmap font.
#include "render/overlay.h"

#include <bit>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "render/bitmap_font.h"

namespace pointrast {
namespace {

constexpr uint32_t kW = 120, kH = 90;
constexpr uint32_t kBlack = 0xFF000000u;

// Looking along +y from (0, -10, 0), z up, 60 degrees vertical field of view.
Camera testCamera() {
  Camera c;
  c.eye = {0, -10, 0};
  c.target = {0, 0, 0};
  c.up = {0, 0, 1};
  c.fovY = 60;
  return c;
}

// The pixel of a world point by the contract of docs/design.md, written out for this camera: view x is
// world x, view y is world z, depth is y + 10.
glm::ivec2 pixelOf(const glm::dvec3& p) {
  const double depth = p.y + 10, f = 1 / std::tan(30.0 * M_PI / 180), aspect = double(kW) / kH;
  const double ndcX = p.x * f / aspect / depth, ndcY = p.z * f / depth;
  return {int(std::floor((ndcX + 1) / 2 * kW)), int(std::floor((1 - ndcY) / 2 * kH))};
}

uint64_t word(float depth, uint32_t color) {
  return uint64_t(std::bit_cast<uint32_t>(depth)) << 32 | color;
}

Annotations one(AnnotationKind kind, std::vector<glm::dvec3> points, std::array<uint8_t, 3> color) {
  Annotations set;
  Annotation a;
  a.kind = kind;
  a.points = std::move(points);
  a.color = color;
  set.items.push_back(a);
  return set;
}

TEST(Overlay, MarkerSitsOnTheProjectedPixel) {
  for (const glm::dvec3 p : {glm::dvec3(0.7, 3, -1.3), glm::dvec3(-2.1, 0.5, 1.9), glm::dvec3(3.3, 8, 2.2)}) {
    std::vector<uint32_t> image(kW * kH, kBlack);
    drawAnnotations({image, kW, kH, {}}, testCamera(), 0.01, one(AnnotationKind::Point, {p}, {255, 0, 0}),
                    {.scale = 1});
    const glm::ivec2 px = pixelOf(p);
    ASSERT_TRUE(px.x >= 3 && px.y >= 3 && px.x < int(kW) - 3 && px.y < int(kH) - 3);
    // The marker is a square of side 7 around the pixel (outline around that), symmetric.
    EXPECT_EQ(image[size_t(px.y) * kW + size_t(px.x)], 0xFF0000FFu);
    for (int d : {-3, 3}) {
      EXPECT_EQ(image[size_t(px.y) * kW + size_t(px.x + d)], 0xFF0000FFu) << d;
      EXPECT_EQ(image[size_t(px.y + d) * kW + size_t(px.x)], 0xFF0000FFu) << d;
      EXPECT_EQ(image[size_t(px.y) * kW + size_t(px.x + d + (d > 0 ? 2 : -2))], kBlack) << d;
    }
  }
}

TEST(Overlay, LineIsHiddenWhereThePointsAreCloser) {
  // A line across the image at depth 15 (y = 5); a wall of points at depth 10 covers the left half.
  const Annotations line = one(AnnotationKind::Distance, {{-4, 5, 0}, {4, 5, 0}}, {0, 255, 0});
  std::vector<uint64_t> words(kW * kH, ~uint64_t(0));
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW / 2; ++x)
      words[y * kW + x] = word(10.0f, 0xFF808080u);
  std::vector<uint32_t> image(kW * kH, kBlack);
  OverlayStyle style;
  style.scale = 1;
  drawAnnotations({image, kW, kH, words}, testCamera(), 0.01, line, style);
  const int row = pixelOf({0, 5, 0}).y;
  const int left = pixelOf({-4, 5, 0}).x, right = pixelOf({4, 5, 0}).x;
  int hidden = 0, shown = 0;
  for (int x = left + 5; x < right - 5; ++x) {
    const bool green = image[size_t(row) * kW + size_t(x)] == 0xFF00FF00u;
    if (x < int(kW) / 2) hidden += !green;
    else shown += green;
  }
  EXPECT_EQ(hidden, kW / 2 - (left + 5));
  EXPECT_EQ(shown, right - 5 - int(kW) / 2);
  // With the wall behind the line instead, all of it shows.
  for (uint64_t& w : words)
    if (w != ~uint64_t(0)) w = word(20.0f, 0xFF808080u);
  std::fill(image.begin(), image.end(), kBlack);
  drawAnnotations({image, kW, kH, words}, testCamera(), 0.01, line, style);
  for (int x = left + 5; x < right - 5; ++x)
    EXPECT_EQ(image[size_t(row) * kW + size_t(x)], 0xFF00FF00u) << x;
}

TEST(Overlay, LineBehindTheEyeIsClippedAtTheNearPlane) {
  // From beside the eye to far ahead: only the part in front of the eye is drawn, no wrap-around.
  const Annotations line = one(AnnotationKind::Distance, {{1, -20, 0}, {1, 30, 0}}, {0, 0, 255});
  std::vector<uint32_t> image(kW * kH, kBlack);
  drawAnnotations({image, kW, kH, {}}, testCamera(), 0.01, line, {.scale = 1});
  const glm::ivec2 far = pixelOf({1, 30, 0});
  EXPECT_EQ(image[size_t(far.y) * kW + size_t(far.x)], 0xFFFF0000u);
  // Left of the far end's marker nothing is drawn (the whole line lies at x = 1 > 0, right of the center).
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < uint32_t(far.x - 4); ++x)
      ASSERT_EQ(image[y * kW + x], kBlack) << x << "," << y;
}

TEST(Overlay, TextDrawsTheGlyphs) {
  std::vector<uint32_t> image(kW * kH, 0xFFFFFFFFu);
  drawText({image, kW, kH, {}}, 10, 10, "1", 0xFF0000FFu, 2);
  const Glyph& g = glyph('1');
  int lit = 0;
  for (int row = 0; row < kGlyphHeight; ++row)
    for (int col = 0; col < kGlyphWidth; ++col) {
      const uint32_t pixel = image[size_t(10 + 2 + row * 2) * kW + size_t(10 + col * 2)];
      EXPECT_EQ(pixel == 0xFF0000FFu, g.pixel(col, row)) << row << "," << col;
      lit += g.pixel(col, row);
    }
  EXPECT_GT(lit, 5);
  EXPECT_EQ(textSize("ab\nc").width, 2 * kGlyphCellWidth);
  EXPECT_EQ(textSize("ab\nc").height, 2 * kGlyphCellHeight);
  EXPECT_EQ(decodeText("m\xC2\xB2 5\xC2\xB0"), (std::vector<uint32_t>{'m', 0xB2, ' ', '5', 0xB0}));
  EXPECT_EQ(&glyph(0x4E2D), &glyph('?'));
  EXPECT_EQ(decodeText("\xFF"), std::vector<uint32_t>{0xFFFDu});
}

} // namespace
} // namespace pointrast

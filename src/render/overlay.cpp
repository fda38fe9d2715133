#include "render/overlay.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "render/bitmap_font.h"

namespace pointrast {

namespace {

constexpr uint32_t kEmptyWord32 = 0xFFFFFFFFu; // the depth half of an empty pixel's word (all ones)
constexpr uint32_t kOutline = 0xFF000000u;      // opaque black around markers

uint32_t rgba(uint8_t r, uint8_t g, uint8_t b) {
  return uint32_t(r) | uint32_t(g) << 8 | uint32_t(b) << 16 | 0xFF000000u;
}

uint32_t kindColor(const Annotation& a) {
  if (a.color) return rgba((*a.color)[0], (*a.color)[1], (*a.color)[2]);
  switch (a.kind) {
  case AnnotationKind::Point:
    return rgba(255, 220, 0);
  case AnnotationKind::Distance:
    return rgba(255, 90, 40);
  case AnnotationKind::Height:
    return rgba(60, 200, 255);
  case AnnotationKind::Area:
    return rgba(110, 255, 110);
  case AnnotationKind::Angle:
    return rgba(255, 110, 255);
  case AnnotationKind::Label:
    return rgba(255, 255, 255);
  case AnnotationKind::ClipBox:
  case AnnotationKind::ClipPolygon:
    return rgba(210, 210, 210);
  }
  return rgba(255, 255, 255);
}

// Mixes `color` over `dst` with weight alpha (0..256).
uint32_t blend(uint32_t dst, uint32_t color, uint32_t alpha) {
  uint32_t out = 0xFF000000u;
  for (int shift = 0; shift < 24; shift += 8) {
    const uint32_t d = (dst >> shift) & 0xFF, c = (color >> shift) & 0xFF;
    out |= ((c * alpha + d * (256 - alpha)) >> 8) << shift;
  }
  return out;
}

// A point seen by the camera: continuous pixel coordinates (the pixel is their floor) and linear depth.
struct ScreenPoint {
  double x = 0, y = 0, w = 0;
};

class Canvas {
public:
  Canvas(const OverlayTarget& target, const Camera& camera, double nearW, const OverlayStyle& style)
      : t_(target), nearW_(nearW), tolerance_(style.depthTolerance),
        scale_(style.scale ? style.scale : std::max(1u, (target.height + 999) / 1000)) {
    assert(target.rgba.size() == size_t(target.width) * target.height);
    assert(target.words.empty() || target.words.size() == target.rgba.size());
    assert(nearW > 0 && camera.shiftX == 0);
    origin_ = camera.eye; // every coordinate relative to the eye, in double
    viewProjection_ = viewProjection(camera, origin_, double(target.width) / double(target.height));
  }

  uint32_t scale() const { return scale_; }

  glm::dvec4 clip(const glm::dvec3& p) const { return viewProjection_ * glm::dvec4(p - origin_, 1.0); }

  ScreenPoint screen(const glm::dvec4& c) const {
    // docs/design.md, "Camera and image": px = floor((x/w + 1)/2 W), py = floor((1 - y/w)/2 H).
    return {(c.x / c.w + 1) / 2 * t_.width, (1 - c.y / c.w) / 2 * t_.height, c.w};
  }

  std::optional<ScreenPoint> project(const glm::dvec3& p) const {
    const glm::dvec4 c = clip(p);
    if (!(c.w > nearW_)) return std::nullopt;
    return screen(c);
  }

  // Whether an overlay pixel at depth w is in front of the frame's point there (or the pixel is empty).
  bool visible(int x, int y, double w) const {
    if (t_.words.empty()) return true;
    const uint64_t word = t_.words[size_t(y) * t_.width + size_t(x)];
    const auto depthBits = uint32_t(word >> 32);
    if (depthBits == kEmptyWord32) return true;
    return w <= double(std::bit_cast<float>(depthBits)) * (1 + tolerance_);
  }

  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < int(t_.width) && y < int(t_.height); }

  void plot(int x, int y, double w, uint32_t color) {
    if (inside(x, y) && visible(x, y, w)) t_.rgba[size_t(y) * t_.width + size_t(x)] = color;
  }

  // A square brush of the line width around (x, y).
  void brush(double x, double y, double w, uint32_t color) {
    const int size = int(scale_);
    const int x0 = int(std::floor(x)) - (size - 1) / 2, y0 = int(std::floor(y)) - (size - 1) / 2;
    for (int dy = 0; dy < size; ++dy)
      for (int dx = 0; dx < size; ++dx)
        plot(x0 + dx, y0 + dy, w, color);
  }

  // The segment a-b in world coordinates, clipped to the near plane and to the image (with a margin), one
  // brush per pixel step; depth interpolated perspective-correctly (1/w is linear on the screen).
  void line(const glm::dvec3& a, const glm::dvec3& b, uint32_t color) {
    glm::dvec4 ca = clip(a), cb = clip(b);
    if (!(ca.w > nearW_) && !(cb.w > nearW_)) return;
    if (!(ca.w > nearW_)) ca = cb + (ca - cb) * ((cb.w - nearW_) / (cb.w - ca.w)) * (1 - 1e-12);
    if (!(cb.w > nearW_)) cb = ca + (cb - ca) * ((ca.w - nearW_) / (ca.w - cb.w)) * (1 - 1e-12);
    const ScreenPoint p = screen(ca), q = screen(cb);
    // Liang-Barsky against the image plus a margin of a few pixels.
    double s0 = 0, s1 = 1;
    const double margin = 4.0 * scale_;
    const double dx = q.x - p.x, dy = q.y - p.y;
    const double edges[4][2] = {{-dx, p.x + margin},
                                {dx, double(t_.width) + margin - p.x},
                                {-dy, p.y + margin},
                                {dy, double(t_.height) + margin - p.y}};
    for (const auto& [d, room] : edges) {
      if (d == 0) {
        if (room < 0) return;
        continue;
      }
      const double s = room / d;
      if (d < 0)
        s0 = std::max(s0, s);
      else
        s1 = std::min(s1, s);
    }
    if (!(s0 <= s1)) return;
    const double length = std::max(std::abs(dx), std::abs(dy)) * (s1 - s0);
    const auto steps = uint64_t(std::ceil(length)) + 1;
    for (uint64_t k = 0; k <= steps; ++k) {
      const double s = s0 + (s1 - s0) * double(k) / double(steps);
      const double inverseW = (1 - s) / p.w + s / q.w;
      brush(p.x + dx * s, p.y + dy * s, 1 / inverseW, color);
    }
  }

  // A square marker with a dark outline around the pixel of p.
  void marker(const glm::dvec3& world, uint32_t color) {
    const std::optional<ScreenPoint> p = project(world);
    if (!p) return;
    const int r = 2 * int(scale_) + 1, cx = int(std::floor(p->x)), cy = int(std::floor(p->y));
    for (int y = -r - 1; y <= r + 1; ++y)
      for (int x = -r - 1; x <= r + 1; ++x) {
        const bool edge = std::max(std::abs(x), std::abs(y)) > r;
        plot(cx + x, cy + y, p->w, edge ? kOutline : color);
      }
  }

  // A label beside the world point, whole when that point passes the depth test, else not at all.
  void label(const glm::dvec3& world, const std::string& text, uint32_t color) {
    if (text.empty()) return;
    const std::optional<ScreenPoint> p = project(world);
    if (!p) return;
    const int cx = int(std::floor(p->x)), cy = int(std::floor(p->y));
    if (!inside(cx, cy) || !visible(cx, cy, p->w)) return;
    const TextSize size = textSize(text);
    const int s = int(scale_);
    // Up and to the right of the point, moved back inside the image where it would leave it.
    int x = cx + 4 * s, y = cy - 4 * s - size.height * s;
    x = std::clamp(x, s, std::max(s, int(t_.width) - size.width * s - s));
    y = std::clamp(y, s, std::max(s, int(t_.height) - size.height * s - s));
    labels_.push_back({x, y, text, color});
  }

  // Labels go over every line and marker.
  void flushLabels() {
    for (const Label& l : labels_)
      drawText(t_, l.x, l.y, l.text, l.color, scale_);
    labels_.clear();
  }

private:
  struct Label {
    int x, y;
    std::string text;
    uint32_t color;
  };
  const OverlayTarget& t_;
  double nearW_, tolerance_;
  uint32_t scale_;
  glm::dvec3 origin_{0};
  glm::dmat4 viewProjection_{1};
  std::vector<Label> labels_;
};

std::string withText(const Annotation& a, const std::string& values) {
  if (a.text.empty()) return values;
  return values.empty() ? a.text : a.text + "\n" + values;
}

glm::dvec3 midpoint(const glm::dvec3& a, const glm::dvec3& b) {
  return (a + b) * 0.5;
}

void drawBox(Canvas& canvas, const OrientedClipBox& box, uint32_t color) {
  glm::dvec3 corners[8];
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 c = box.center;
    for (int a = 0; a < 3; ++a)
      c += box.axes[size_t(a)] * box.halfExtent[a] * ((i >> a) & 1 ? 1.0 : -1.0);
    corners[i] = c;
  }
  for (int i = 0; i < 8; ++i)
    for (int a = 0; a < 3; ++a)
      if (!((i >> a) & 1)) canvas.line(corners[i], corners[i | (1 << a)], color);
}

// The rings at each finite end of the z range, and the vertical edges when both are finite. A polygon
// unbounded in z on both sides has no height to draw it at and is not drawn.
void drawPolygon(Canvas& canvas, const ClipPolygon& polygon, uint32_t color) {
  const size_t n = polygon.vertices.size();
  for (double z : {polygon.zMin, polygon.zMax}) {
    if (!std::isfinite(z)) continue;
    for (size_t i = 0; i < n; ++i) {
      const glm::dvec2 a = polygon.vertices[i], b = polygon.vertices[(i + 1) % n];
      canvas.line({a, z}, {b, z}, color);
    }
  }
  if (std::isfinite(polygon.zMin) && std::isfinite(polygon.zMax))
    for (const glm::dvec2& v : polygon.vertices)
      canvas.line({v, polygon.zMin}, {v, polygon.zMax}, color);
}

void drawOne(Canvas& canvas, const Annotation& a, const std::string& unit) {
  const uint32_t color = kindColor(a);
  const std::vector<glm::dvec3>& p = a.points;
  const Measurement m = measure(a);
  const std::string area = unit.empty() ? std::string() : unit + "\xC2\xB2"; // superscript two
  switch (a.kind) {
  case AnnotationKind::Point:
  case AnnotationKind::Label:
    canvas.marker(p[0], color);
    canvas.label(p[0], a.text, color);
    break;
  case AnnotationKind::Distance:
    for (size_t i = 1; i < p.size(); ++i)
      canvas.line(p[i - 1], p[i], color);
    for (const glm::dvec3& q : p)
      canvas.marker(q, color);
    if (p.size() == 2) {
      canvas.label(midpoint(p[0], p[1]), withText(a, formatLength(m.length, unit)), color);
    } else {
      for (size_t i = 1; i < p.size(); ++i)
        canvas.label(midpoint(p[i - 1], p[i]), formatLength(m.segments[i - 1], unit), color);
      canvas.label(p.back(), withText(a, "total " + formatLength(m.length, unit)), color);
    }
    break;
  case AnnotationKind::Height: {
    // The slope line and the right triangle under it: horizontal leg at the lower point's height, then
    // the vertical leg.
    const bool rising = p[1].z >= p[0].z;
    const glm::dvec3& low = rising ? p[0] : p[1];
    const glm::dvec3& high = rising ? p[1] : p[0];
    const glm::dvec3 corner(high.x, high.y, low.z);
    canvas.line(p[0], p[1], color);
    canvas.line(low, corner, color);
    canvas.line(corner, high, color);
    canvas.marker(p[0], color);
    canvas.marker(p[1], color);
    canvas.label(midpoint(corner, high),
                 withText(a, std::string("dz ") + (m.dz >= 0 ? "+" : "") + formatLength(m.dz, unit) + "\nhoriz " +
                                 formatLength(m.horizontal, unit) + "\nslope " + formatLength(m.slope, unit)),
                 color);
    break;
  }
  case AnnotationKind::Area: {
    glm::dvec3 center(0);
    for (size_t i = 0; i < p.size(); ++i) {
      canvas.line(p[i], p[(i + 1) % p.size()], color);
      center += p[i] / double(p.size());
    }
    for (const glm::dvec3& q : p)
      canvas.marker(q, color);
    std::string value = formatLength(m.area, "");
    if (!area.empty()) value += " " + area;
    canvas.label(center, withText(a, value + "\nperimeter " + formatLength(m.perimeter, unit)), color);
    break;
  }
  case AnnotationKind::Angle: {
    canvas.line(p[0], p[1], color);
    canvas.line(p[1], p[2], color);
    for (const glm::dvec3& q : p)
      canvas.marker(q, color);
    char degrees[32];
    std::snprintf(degrees, sizeof degrees, "%.1f\xC2\xB0", m.degrees);
    canvas.label(p[1], withText(a, degrees), color);
    break;
  }
  case AnnotationKind::ClipBox:
    drawBox(canvas, a.box, color);
    canvas.label(a.box.center, a.text, color);
    break;
  case AnnotationKind::ClipPolygon:
    drawPolygon(canvas, a.polygon, color);
    if (std::isfinite(a.polygon.zMax)) canvas.label({a.polygon.vertices[0], a.polygon.zMax}, a.text, color);
    break;
  }
}

} // namespace

void drawAnnotations(const OverlayTarget& target, const Camera& camera, double nearW,
                     const Annotations& annotations, const OverlayStyle& style) {
  if (target.width == 0 || target.height == 0) return;
  Canvas canvas(target, camera, nearW, style);
  for (const Annotation& a : annotations.items)
    drawOne(canvas, a, annotations.unit);
  canvas.flushLabels();
}

void drawText(const OverlayTarget& target, int x, int y, std::string_view utf8, uint32_t color, uint32_t scale) {
  const int s = int(std::max(1u, scale));
  const TextSize size = textSize(utf8);
  auto put = [&](int px, int py, uint32_t c, uint32_t alpha) {
    if (px < 0 || py < 0 || px >= int(target.width) || py >= int(target.height)) return;
    uint32_t& dst = target.rgba[size_t(py) * target.width + size_t(px)];
    dst = alpha >= 256 ? c : blend(dst, c, alpha);
  };
  // A translucent dark box keeps the text readable over any points.
  for (int py = y - s; py < y + size.height * s + s; ++py)
    for (int px = x - s; px < x + size.width * s + s; ++px)
      put(px, py, 0xFF000000u, 160);
  int column = 0, line = 0;
  for (uint32_t c : decodeText(utf8)) {
    if (c == kNewline) {
      ++line;
      column = 0;
      continue;
    }
    const Glyph& g = glyph(c);
    const int gx = x + column * kGlyphCellWidth * s, gy = y + (line * kGlyphCellHeight + 1) * s;
    for (int row = 0; row < kGlyphHeight; ++row)
      for (int col = 0; col < kGlyphWidth; ++col)
        if (g.pixel(col, row))
          for (int dy = 0; dy < s; ++dy)
            for (int dx = 0; dx < s; ++dx)
              put(gx + col * s + dx, gy + row * s + dy, color, 256);
    ++column;
  }
}

} // namespace pointrast

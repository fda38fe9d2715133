#include "cloud/annotations.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace pointrast {

namespace {

struct KindName {
  AnnotationKind kind;
  const char* name;
};
constexpr KindName kKindNames[] = {
    {AnnotationKind::Point, "point"},       {AnnotationKind::Distance, "distance"},
    {AnnotationKind::Height, "height"},     {AnnotationKind::Area, "area"},
    {AnnotationKind::Angle, "angle"},       {AnnotationKind::Label, "label"},
    {AnnotationKind::ClipBox, "clip-box"},  {AnnotationKind::ClipPolygon, "clip-polygon"},
};

bool finiteCoordinate(double v) {
  return std::isfinite(v) && std::abs(v) <= kMaxAnnotationCoordinate;
}

bool finitePoint(const glm::dvec3& p) {
  return finiteCoordinate(p.x) && finiteCoordinate(p.y) && finiteCoordinate(p.z);
}

// The points a kind takes: exactly `min` when max == min, at least `min` when max is 0.
struct PointCount {
  size_t min, max;
};
PointCount pointCount(AnnotationKind kind) {
  switch (kind) {
  case AnnotationKind::Point:
  case AnnotationKind::Label:
    return {1, 1};
  case AnnotationKind::Distance:
    return {2, 0};
  case AnnotationKind::Height:
    return {2, 2};
  case AnnotationKind::Area:
    return {3, 0};
  case AnnotationKind::Angle:
    return {3, 3};
  case AnnotationKind::ClipBox:
  case AnnotationKind::ClipPolygon:
    return {0, 0};
  }
  return {0, 0};
}

std::string boxProblem(const OrientedClipBox& box) {
  if (!finitePoint(box.center)) return "the box's center is not a finite coordinate";
  for (int a = 0; a < 3; ++a)
    if (!(std::isfinite(box.halfExtent[a]) && box.halfExtent[a] >= 0))
      return "the box's half extents must be finite and >= 0";
  for (int a = 0; a < 3; ++a) {
    const glm::dvec3& axis = box.axes[size_t(a)];
    if (!(std::isfinite(axis.x) && std::isfinite(axis.y) && std::isfinite(axis.z)))
      return "the box's axes are not finite";
    for (int b = 0; b < 3; ++b) {
      const double expected = a == b ? 1.0 : 0.0;
      if (!(std::abs(glm::dot(axis, box.axes[size_t(b)]) - expected) <= 1e-6))
        return "the box's axes are not orthonormal";
    }
  }
  return {};
}

std::string polygonProblem(const ClipPolygon& polygon) {
  if (polygon.vertices.size() < 3) return "the polygon needs at least 3 vertices";
  for (const glm::dvec2& v : polygon.vertices)
    if (!finiteCoordinate(v.x) || !finiteCoordinate(v.y)) return "the polygon's vertices are not finite coordinates";
  if (std::isnan(polygon.zMin) || std::isnan(polygon.zMax) || !(polygon.zMin <= polygon.zMax))
    return "the polygon's z range is empty (z_min > z_max)";
  if (polygon.zMin == std::numeric_limits<double>::infinity() ||
      polygon.zMax == -std::numeric_limits<double>::infinity())
    return "the polygon's z range is empty";
  return {};
}

double horizontalDistance(const glm::dvec3& a, const glm::dvec3& b) {
  return std::hypot(b.x - a.x, b.y - a.y);
}

} // namespace

const char* annotationKindName(AnnotationKind kind) {
  for (const KindName& k : kKindNames)
    if (k.kind == kind) return k.name;
  return "?";
}

std::optional<AnnotationKind> parseAnnotationKind(const std::string& name) {
  for (const KindName& k : kKindNames)
    if (name == k.name) return k.kind;
  return std::nullopt;
}

std::string annotationProblem(const Annotation& a) {
  const PointCount count = pointCount(a.kind);
  if (count.max == count.min && a.points.size() != count.min)
    return "needs exactly " + std::to_string(count.min) + " point" + (count.min == 1 ? "" : "s") + ", not " +
           std::to_string(a.points.size());
  if (count.max == 0 && a.points.size() < count.min)
    return "needs at least " + std::to_string(count.min) + " points, not " + std::to_string(a.points.size());
  for (const glm::dvec3& p : a.points)
    if (!finitePoint(p))
      return "a point is not a finite coordinate within " + std::to_string(int64_t(kMaxAnnotationCoordinate));
  if (a.kind == AnnotationKind::Label && a.text.empty()) return "a label needs a text";
  if (a.kind == AnnotationKind::Angle &&
      (glm::length(a.points[0] - a.points[1]) == 0 || glm::length(a.points[2] - a.points[1]) == 0))
    return "an angle's outer points must differ from its middle point";
  if (a.kind == AnnotationKind::ClipBox) return boxProblem(a.box);
  if (a.kind == AnnotationKind::ClipPolygon) return polygonProblem(a.polygon);
  return {};
}

Measurement measure(const Annotation& a) {
  assert(annotationProblem(a).empty());
  Measurement m;
  const std::vector<glm::dvec3>& p = a.points;
  switch (a.kind) {
  case AnnotationKind::Distance:
    for (size_t i = 1; i < p.size(); ++i) {
      m.segments.push_back(glm::length(p[i] - p[i - 1]));
      m.length += m.segments.back();
    }
    break;
  case AnnotationKind::Height:
    m.dz = p[1].z - p[0].z;
    m.horizontal = horizontalDistance(p[0], p[1]);
    m.slope = glm::length(p[1] - p[0]);
    break;
  case AnnotationKind::Area: {
    // Shoelace on coordinates relative to the first vertex: UTM-sized values would cancel catastrophically.
    double twice = 0;
    for (size_t i = 0; i < p.size(); ++i) {
      const glm::dvec3& a0 = p[i];
      const glm::dvec3& a1 = p[(i + 1) % p.size()];
      const double x0 = a0.x - p[0].x, y0 = a0.y - p[0].y, x1 = a1.x - p[0].x, y1 = a1.y - p[0].y;
      twice += x0 * y1 - x1 * y0;
      m.perimeter += horizontalDistance(a0, a1);
      m.perimeter3d += glm::length(a1 - a0);
    }
    m.area = std::abs(twice) / 2;
    break;
  }
  case AnnotationKind::Angle: {
    const glm::dvec3 u = glm::normalize(p[0] - p[1]), v = glm::normalize(p[2] - p[1]);
    // atan2 of |u x v| and u . v keeps precision near 0 and 180 degrees, where acos does not.
    m.degrees = std::atan2(glm::length(glm::cross(u, v)), glm::dot(u, v)) * 180.0 / std::numbers::pi;
    break;
  }
  default:
    break;
  }
  return m;
}

PointFilter clipVolumes(const Annotations& annotations) {
  PointFilter filter;
  for (const Annotation& a : annotations.items) {
    if (a.kind == AnnotationKind::ClipBox) filter.orientedBoxes.push_back(a.box);
    if (a.kind == AnnotationKind::ClipPolygon) filter.polygons.push_back(a.polygon);
  }
  return filter;
}

std::string formatLength(double value, const std::string& unit) {
  char text[64];
  std::snprintf(text, sizeof text, std::abs(value) < 100000 ? "%.2f" : "%.0f", value);
  return unit.empty() ? std::string(text) : std::string(text) + " " + unit;
}

} // namespace pointrast

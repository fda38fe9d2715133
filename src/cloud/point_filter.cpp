// Point filters on the CPU: the rules of point_filter.h, point by point and box by box.
#include "cloud/point_filter.h"

#include <algorithm>
#include <cmath>

#include "base/error.h"

namespace pointrast {

namespace {

bool insideBox(const ClipBox& b, const glm::dvec3& p) {
  return b.min.x <= p.x && p.x <= b.max.x && b.min.y <= p.y && p.y <= b.max.y && b.min.z <= p.z &&
         p.z <= b.max.z;
}

bool insideOriented(const OrientedClipBox& b, const glm::dvec3& p) {
  const glm::dvec3 d = p - b.center;
  for (int i = 0; i < 3; ++i)
    if (!(std::abs(glm::dot(d, b.axes[size_t(i)])) <= b.halfExtent[i])) return false;
  return true;
}

// The crossing rule exactly as the header spells it (the GPU evaluates the same expression).
bool insidePolygonXY(const std::vector<glm::dvec2>& v, double x, double y) {
  bool inside = false;
  const size_t n = v.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const glm::dvec2 a = v[j], b = v[i];
    if ((b.y > y) != (a.y > y) && x < (a.x - b.x) * (y - b.y) / (a.y - b.y) + b.x) inside = !inside;
  }
  return inside;
}

bool insidePolygon(const ClipPolygon& poly, const glm::dvec3& p) {
  if (poly.vertices.size() < 3 || !(poly.zMin <= p.z && p.z <= poly.zMax)) return false;
  return insidePolygonXY(poly.vertices, p.x, p.y);
}

// Whether every point of a box is inside, none is, or it depends. A box's verdict must hold for every
// point within it, so "All" and "None" keep a margin of a few ulps of the coordinates to the volume's
// boundary, where the point test's own rounding could decide either way.
enum class Inside : uint8_t { None, Some, All };

double margin(const Bounds& box) {
  const double extent = std::max({std::abs(box.min.x), std::abs(box.min.y), std::abs(box.min.z),
                                  std::abs(box.max.x), std::abs(box.max.y), std::abs(box.max.z), 1.0});
  return extent * 1e-12;
}

Inside relateBox(const ClipBox& c, const Bounds& box, double eps) {
  for (int a = 0; a < 3; ++a)
    if (box.max[a] < c.min[a] - eps || box.min[a] > c.max[a] + eps) return Inside::None;
  for (int a = 0; a < 3; ++a)
    if (!(box.min[a] >= c.min[a] + eps && box.max[a] <= c.max[a] - eps)) return Inside::Some;
  return Inside::All;
}

// Separating axes of the oriented box's faces only: a box outside along none of them may still miss the
// oriented box (then Some, which is always correct).
Inside relateOriented(const OrientedClipBox& c, const Bounds& box, double eps) {
  const glm::dvec3 center = box.center(), half = 0.5 * box.size();
  bool all = true;
  for (int i = 0; i < 3; ++i) {
    const glm::dvec3& axis = c.axes[size_t(i)];
    const double d = std::abs(glm::dot(center - c.center, axis));
    const double r = std::abs(axis.x) * half.x + std::abs(axis.y) * half.y + std::abs(axis.z) * half.z;
    if (d - r > c.halfExtent[i] + eps) return Inside::None;
    if (!(d + r <= c.halfExtent[i] - eps)) all = false;
  }
  return all ? Inside::All : Inside::Some;
}

// Whether segment ab touches the closed rectangle [lo, hi] (Liang-Barsky clipping).
bool segmentTouchesRect(glm::dvec2 a, glm::dvec2 b, glm::dvec2 lo, glm::dvec2 hi) {
  double t0 = 0, t1 = 1;
  const glm::dvec2 d = b - a;
  for (int k = 0; k < 2; ++k) {
    if (d[k] == 0) {
      if (a[k] < lo[k] || a[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - a[k]) / d[k], tb = (hi[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

// No edge touches the (slightly grown) rectangle: then the rectangle lies wholly inside or wholly outside,
// and its center says which.
Inside relatePolygon(const ClipPolygon& poly, const Bounds& box, double eps) {
  if (poly.vertices.size() < 3) return Inside::None;
  if (box.max.z < poly.zMin - eps || box.min.z > poly.zMax + eps) return Inside::None;
  const glm::dvec2 lo = glm::dvec2(box.min) - eps, hi = glm::dvec2(box.max) + eps;
  const size_t n = poly.vertices.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++)
    if (segmentTouchesRect(poly.vertices[j], poly.vertices[i], lo, hi)) return Inside::Some;
  const glm::dvec3 c = box.center();
  if (!insidePolygonXY(poly.vertices, c.x, c.y)) return Inside::None;
  return box.min.z >= poly.zMin + eps && box.max.z <= poly.zMax - eps ? Inside::All : Inside::Some;
}

} // namespace

FilterNeeds filterNeeds(const PointFilter& filter) {
  FilterNeeds n;
  n.classification = filter.classes.has_value();
  n.returnNumber = filter.returns != ReturnFilter::All;
  n.numberOfReturns = filter.returns == ReturnFilter::Last || filter.returns == ReturnFilter::Only;
  n.intensity = filter.intensity.has_value();
  n.gpsTime = filter.gpsTime.has_value();
  n.pointSourceId = filter.sourceIds.has_value();
  return n;
}

void requireFilterAttributes(const PointFilter& filter, const FilterNeeds& has, const std::string& source) {
  const FilterNeeds need = filterNeeds(filter);
  auto refuse = [&](const char* option, const char* attribute) {
    throw InputError(source + ": " + option + " filters on " + attribute +
                     ", which this input does not have");
  };
  if (need.classification && !has.classification) refuse("--classes", "the classification");
  const char* returns = filter.returns == ReturnFilter::First  ? "--returns first"
                        : filter.returns == ReturnFilter::Last ? "--returns last"
                                                               : "--returns only";
  if (need.returnNumber && !has.returnNumber) refuse(returns, "the return number");
  if (need.numberOfReturns && !has.numberOfReturns) refuse(returns, "the number of returns");
  if (need.intensity && !has.intensity) refuse("--intensity", "the intensity");
  if (need.gpsTime && !has.gpsTime) refuse("--gps-time", "the GPS time");
  if (need.pointSourceId && !has.pointSourceId) refuse("--source-ids", "the point source id");
}

bool insideClip(const PointFilter& filter, const glm::dvec3& p) {
  for (const ClipBox& b : filter.boxes)
    if (insideBox(b, p)) return true;
  for (const OrientedClipBox& b : filter.orientedBoxes)
    if (insideOriented(b, p)) return true;
  for (const ClipPolygon& poly : filter.polygons)
    if (insidePolygon(poly, p)) return true;
  return false;
}

bool passes(const PointFilter& filter, const FilterPoint& p) {
  if (filter.classes && !(*filter.classes)[p.classification]) return false;
  switch (filter.returns) {
  case ReturnFilter::All:
    break;
  case ReturnFilter::First:
    if (p.returnNumber != 1) return false;
    break;
  case ReturnFilter::Last:
    if (p.returnNumber == 0 || p.returnNumber != p.numberOfReturns) return false;
    break;
  case ReturnFilter::Only:
    if (p.returnNumber == 0 || p.numberOfReturns != 1) return false;
    break;
  }
  if (filter.intensity &&
      !(filter.intensity->first <= p.intensity && p.intensity <= filter.intensity->second))
    return false;
  if (filter.gpsTime && !(filter.gpsTime->first <= p.gpsTime && p.gpsTime <= filter.gpsTime->second))
    return false;
  if (filter.sourceIds &&
      !std::binary_search(filter.sourceIds->begin(), filter.sourceIds->end(), p.pointSourceId))
    return false;
  if (!filter.hasClip() || filter.clipMode == ClipMode::Highlight) return true;
  return insideClip(filter, p.position) == (filter.clipMode == ClipMode::Inside);
}

BoxVerdict clipVerdict(const PointFilter& filter, const Bounds& box) {
  if (!filter.hasClip() || filter.clipMode == ClipMode::Highlight) return BoxVerdict::All;
  if (box.empty()) return BoxVerdict::None; // holds no point
  const double eps = margin(box);
  Inside inside = Inside::None;
  auto unite = [&inside](Inside v) {
    if (v == Inside::All)
      inside = Inside::All;
    else if (v == Inside::Some && inside == Inside::None)
      inside = Inside::Some;
  };
  for (const ClipBox& b : filter.boxes)
    unite(relateBox(b, box, eps));
  for (const OrientedClipBox& b : filter.orientedBoxes)
    unite(relateOriented(b, box, eps));
  for (const ClipPolygon& poly : filter.polygons)
    unite(relatePolygon(poly, box, eps));
  if (inside == Inside::Some) return BoxVerdict::Some;
  const bool allInside = inside == Inside::All;
  return allInside == (filter.clipMode == ClipMode::Inside) ? BoxVerdict::All : BoxVerdict::None;
}

FilterNeeds filterFields(const PointCloud& cloud) {
  FilterNeeds has;
  has.classification = !cloud.classification.empty();
  has.returnNumber = !cloud.returnNumber.empty();
  has.intensity = !cloud.intensity.empty();
  has.pointSourceId = !cloud.pointSourceId.empty();
  return has;
}

void applyFilter(PointCloud& cloud, const PointFilter& filter) {
  if (!filter.active()) return;
  const uint64_t n = cloud.size();
  uint64_t kept = 0;
  for (uint64_t i = 0; i < n; ++i) {
    FilterPoint p;
    p.position = cloud.world(i);
    if (!cloud.classification.empty()) p.classification = cloud.classification[i];
    if (!cloud.returnNumber.empty()) p.returnNumber = cloud.returnNumber[i];
    if (!cloud.intensity.empty()) p.intensity = cloud.intensity[i];
    if (!cloud.pointSourceId.empty()) p.pointSourceId = cloud.pointSourceId[i];
    if (!passes(filter, p)) continue;
    for (int a = 0; a < 3; ++a)
      cloud.positions[3 * kept + a] = cloud.positions[3 * i + a];
    if (!cloud.colors.empty()) cloud.colors[kept] = cloud.colors[i];
    if (!cloud.intensity.empty()) cloud.intensity[kept] = cloud.intensity[i];
    if (!cloud.classification.empty()) cloud.classification[kept] = cloud.classification[i];
    if (!cloud.returnNumber.empty()) cloud.returnNumber[kept] = cloud.returnNumber[i];
    if (!cloud.pointSourceId.empty()) cloud.pointSourceId[kept] = cloud.pointSourceId[i];
    ++kept;
  }
  cloud.positions.resize(3 * kept);
  if (!cloud.colors.empty()) cloud.colors.resize(kept);
  if (!cloud.intensity.empty()) cloud.intensity.resize(kept);
  if (!cloud.classification.empty()) cloud.classification.resize(kept);
  if (!cloud.returnNumber.empty()) cloud.returnNumber.resize(kept);
  if (!cloud.pointSourceId.empty()) cloud.pointSourceId.resize(kept);
  computeBounds(cloud);
}

} // namespace pointrast

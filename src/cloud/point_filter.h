// Which points a user wants to see or keep: clip volumes in the file's coordinates and attribute filters.
// One model for every consumer: `convert` and `profile` evaluate it on the CPU record by record, the
// renderer evaluates the same rules on the GPU (and culls whole nodes and batches with relate()), the
// viewers edit it in their panels. The command-line options that fill it live in app/options.h.
//
// Rules (the CPU and the GPU must agree on every point):
//   - Clip volumes: a point is "inside" when it lies in at least one volume (the union). Boundaries count
//     as inside (min <= p <= max). ClipMode::Inside keeps the inside points, Outside the others, Highlight
//     keeps every point and marks the inside ones. No volume: every point passes the clip.
//   - Oriented box: |dot(p - center, axes[i])| <= halfExtent[i] for i = 0, 1, 2.
//   - Polygon: zMin <= z <= zMax and the even-odd crossing rule in x/y, evaluated exactly as
//         inside = false; for each edge (a = v[j], b = v[i]), j = i - 1 (j = n - 1 for i = 0):
//           if ((b.y > y) != (a.y > y) && x < (a.x - b.x) * (y - b.y) / (a.y - b.y) + b.x) inside = !inside
//     (a point exactly on an edge may fall either way; a node's or batch's verdict never depends on it).
//   - Attribute filters combine with AND; each one that is unset passes every point.
//   - Returns: First is return number 1; Last is return number == number of returns; Only is a single
//     return (number of returns 1). A return number of 0 (files that do not record it) fails First, Last
//     and Only.
//   - Ranges are closed: lo <= value <= hi.
#pragma once

#include <array>
#include <bitset>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "cloud/cloud.h"

namespace pointrast {

// Axis-aligned box, world coordinates of the file (scale and offset applied).
struct ClipBox {
  glm::dvec3 min{0}, max{0};
  bool operator==(const ClipBox&) const = default;
};

// A box of any orientation: center, three orthonormal axes and the half extent along each.
struct OrientedClipBox {
  glm::dvec3 center{0};
  std::array<glm::dvec3, 3> axes{glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1)};
  glm::dvec3 halfExtent{0};
  bool operator==(const OrientedClipBox&) const = default;
};

// A simple polygon in x/y, extruded along z between zMin and zMax (unbounded by default). Even-odd rule.
struct ClipPolygon {
  std::vector<glm::dvec2> vertices; // at least 3
  double zMin = -std::numeric_limits<double>::infinity();
  double zMax = std::numeric_limits<double>::infinity();
  bool operator==(const ClipPolygon&) const = default;
};

enum class ClipMode : uint8_t { Inside, Outside, Highlight };
enum class ReturnFilter : uint8_t { All, First, Last, Only };

struct PointFilter {
  std::vector<ClipBox> boxes;
  std::vector<OrientedClipBox> orientedBoxes;
  std::vector<ClipPolygon> polygons;
  ClipMode clipMode = ClipMode::Inside;

  std::optional<std::bitset<256>> classes; // the classification values to keep
  ReturnFilter returns = ReturnFilter::All;
  std::optional<std::pair<double, double>> intensity; // closed range
  std::optional<std::pair<double, double>> gpsTime;   // closed range
  std::optional<std::vector<uint16_t>> sourceIds;     // point source ids to keep (sorted, unique)

  bool hasClip() const { return !boxes.empty() || !orientedBoxes.empty() || !polygons.empty(); }
  bool hasAttributeFilter() const {
    return classes || returns != ReturnFilter::All || intensity || gpsTime || sourceIds;
  }
  // Whether any point could be dropped or marked.
  bool active() const { return hasClip() || hasAttributeFilter(); }
  bool operator==(const PointFilter&) const = default;
};

// One point as the filter sees it. Fields the input lacks are 0 (the caller checks needs() first).
struct FilterPoint {
  glm::dvec3 position{0};
  uint8_t classification = 0;
  uint8_t returnNumber = 0;
  uint8_t numberOfReturns = 0;
  uint16_t intensity = 0;
  double gpsTime = 0;
  uint16_t pointSourceId = 0;
};

// The attributes a filter reads.
struct FilterNeeds {
  bool classification = false, returnNumber = false, numberOfReturns = false, intensity = false,
       gpsTime = false, pointSourceId = false;
};
FilterNeeds filterNeeds(const PointFilter& filter);
// InputError naming the option (--classes, --returns, ...) and the attribute when `filter` reads an
// attribute that `has` lacks; `source` names the input in the message.
void requireFilterAttributes(const PointFilter& filter, const FilterNeeds& has, const std::string& source);

// Inside at least one clip volume (false when there is none).
bool insideClip(const PointFilter& filter, const glm::dvec3& p);
// Whether the point is kept (Highlight keeps every point that passes the attribute filters).
bool passes(const PointFilter& filter, const FilterPoint& p);

// How an axis-aligned world box (a node's or a batch's bounds) relates to the clip: every point it may hold
// is kept (All), none is (None), or it must be tested point by point (Some). Conservative: Some is always a
// correct answer; All and None must be exact for every point within the box. Attribute filters are not
// considered (a box with no clip volume is All).
enum class BoxVerdict : uint8_t { None, Some, All };
BoxVerdict clipVerdict(const PointFilter& filter, const Bounds& box);

// The attributes a cloud in memory holds (it keeps neither the number of returns nor GPS times).
FilterNeeds filterFields(const PointCloud& cloud);
// Keeps the points of a cloud in memory that pass, in their order; bounds recomputed. The caller has
// checked filterFields() with requireFilterAttributes().
void applyFilter(PointCloud& cloud, const PointFilter& filter);

} // namespace pointrast

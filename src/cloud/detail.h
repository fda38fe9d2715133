// Helpers shared by the files of src/cloud/, not part of the library's interface.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>

#include "cloud/cloud.h"

namespace pointrast::detail {

// Per-axis extremes of quantized positions. Kept as integers so a merge is exact and cheap; the world
// bounds follow from the two corners because q * scale + offset is monotonic in q.
struct QuantBox {
  int32_t min[3] = {std::numeric_limits<int32_t>::max(), std::numeric_limits<int32_t>::max(),
                    std::numeric_limits<int32_t>::max()};
  int32_t max[3] = {std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::min(),
                    std::numeric_limits<int32_t>::min()};

  bool empty() const { return min[0] > max[0]; }
  void expand(const QuantBox& b) {
    for (int a = 0; a < 3; ++a) {
      min[a] = std::min(min[a], b.min[a]);
      max[a] = std::max(max[a], b.max[a]);
    }
  }
};

// Serial scan of points [first, first + count) of a positions array (3 int32 per point).
QuantBox quantBox(const int32_t* positions, uint64_t first, uint64_t count);
// The same over all points, on all hardware threads.
QuantBox quantBoxParallel(const int32_t* positions, uint64_t count);

// World bounds of the points a box was taken from, computed exactly as PointCloud::world() would.
Bounds worldBounds(const QuantBox& box, const glm::dvec3& scale, const glm::dvec3& offset);

// A perceptual rainbow ("Turbo", Mikhailov 2019, polynomial fit) for t in [0, 1], as packRgba.
uint32_t rampColor(double t);

} // namespace pointrast::detail

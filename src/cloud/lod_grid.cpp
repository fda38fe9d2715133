#include "cloud/lod_grid.h"

#include <cassert>
#include <cmath>

namespace pointrast::lod {

LodGrid makeLodGrid(const detail::QuantBox& box, const glm::dvec3& scale, const glm::dvec3& offset,
                    int gridLevels) {
  assert(!box.empty());
  assert(scale.x > 0 && scale.y > 0 && scale.z > 0);
  assert(gridLevels >= 1 && gridLevels <= 14);
  LodGrid grid;
  grid.gridLevels = gridLevels;
  grid.scale = scale;
  grid.offset = offset;
  double edge = 0;
  for (int a = 0; a < 3; ++a) {
    grid.qmin[a] = box.min[a];
    // int64: the extent of int32 coordinates needs 33 bits.
    edge = std::max(edge, double(int64_t(box.max[a]) - box.min[a] + 1) * scale[a]);
  }
  for (int a = 0; a < 3; ++a) {
    grid.cube.min[a] = double(box.min[a]) * scale[a] + offset[a];
    grid.cube.max[a] = grid.cube.min[a] + edge;
    grid.toCode[a] = double(1u << kCodeLevels) * scale[a] / edge;
  }
  return grid;
}

int gridLevelsForSpacing(double edge, double spacing) {
  if (!(spacing > 0) || !(edge > 0)) return kDefaultGridLevels;
  const double levels = std::round(std::log2(edge / spacing));
  return static_cast<int>(std::clamp(levels, 4.0, 14.0));
}

} // namespace pointrast::lod

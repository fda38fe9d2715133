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
  int64_t extent = 0;
  for (int a = 0; a < 3; ++a)
    extent = std::max(extent, int64_t(box.max[a]) - box.min[a] + 1);
  grid.isotropic = scale.x == scale.y && scale.y == scale.z;
  grid.edgeQuanta = grid.isotropic ? extent : 0;
  for (int a = 0; a < 3; ++a) {
    grid.cube.min[a] = double(box.min[a]) * scale[a] + offset[a];
    grid.cube.max[a] = grid.cube.min[a] + edge;
    grid.toCode[a] = double(1u << kCodeLevels) * scale[a] / edge;
  }
  return grid;
}

LodGrid::Center LodGrid::cellCenter(uint64_t cell, int cellLevel) const {
  const uint32_t index[3] = {detail::compactBits3(cell >> 2), detail::compactBits3(cell >> 1),
                             detail::compactBits3(cell)};
  Center c;
  for (int a = 0; a < 3; ++a) {
    if (isotropic) {
      // 2 qmin + (2 i + 1) * E / 2^level, rounded: (2 i + 1) * E < 2^22 * 2^33 fits int64.
      const int64_t num = (2 * int64_t(index[a]) + 1) * edgeQuanta;
      c.twice[a] = 2 * int64_t(qmin[a]) + ((num + (int64_t(1) << cellLevel >> 1)) >> cellLevel);
    } else {
      const double edgeQ = double(uint64_t(1) << kCodeLevels) / toCode[a]; // the cube's edge in quanta
      c.twice[a] = 2 * int64_t(qmin[a]) +
                   int64_t(std::llround((2.0 * index[a] + 1) * edgeQ / double(uint64_t(1) << cellLevel)));
    }
  }
  return c;
}

int gridLevelsForSpacing(double edge, double spacing) {
  if (!(spacing > 0) || !(edge > 0)) return kDefaultGridLevels;
  const double levels = std::round(std::log2(edge / spacing));
  return static_cast<int>(std::clamp(levels, 4.0, 14.0));
}

} // namespace pointrast::lod

#version 460
// One level's subsample (cloud/lod_index.h has the rules): the first thread of each grid cell's run of
// sorted points picks, among the cell's points no level above took, the one nearest the cell's center
// (the first in sorted order on a tie), marks it taken at this level and gives it the average color of
// the points it stands for. Only in inner nodes: above the chunk's level every node is; from there on
// a node is inner when its cube holds more than leafPoints points, which two binary searches over the
// sorted codes count. The grid is isotropic (equal scales), so distances are exact integers.
#include "lod_index.inc.glsl"

layout(local_size_x = kIndexGroupSize) in;
layout(push_constant) uniform Push { IndexLevelPush pc; };

// The first sorted point whose code >> shift is at least `key`, in [lo, hi).
uint lowerBound(IndexItems items, uint lo, uint hi, uint shift, uint64_t key) {
  while (lo < hi) {
    const uint mid = lo + (hi - lo) / 2;
    if ((items.v[mid].code >> shift) < key)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

void main() {
  const uint i = linearInvocation(pc.groupsX, kIndexGroupSize);
  if (i >= pc.count) return;
  IndexItems items = IndexItems(pc.sorted);
  const uint cellShift = 3 * (kIndexCodeLevels - pc.cellLevel);
  const uint64_t cell = items.v[i].code >> cellShift;
  if (i > 0 && (items.v[i - 1].code >> cellShift) == cell) return; // not the cell's first point
  if (pc.level >= pc.chunkLevel) {
    const uint nodeShift = 3 * (kIndexCodeLevels - pc.level);
    const uint64_t node = cell >> (nodeShift - cellShift);
    const uint first = lowerBound(items, 0, i, nodeShift, node);
    const uint end = lowerBound(items, i, pc.count, nodeShift, node + 1);
    if (uint64_t(end - first) <= pc.leafPoints) return; // a leaf: its points stay
  }
  UintArray taken = UintArray(pc.taken);
  int64_t center[3];
  const uint index[3] = uint[3](compactBits3(cell >> 2), compactBits3(cell >> 1), compactBits3(cell));
  for (int a = 0; a < 3; ++a) {
    // 2 qmin + (2 i + 1) * E / 2^level, rounded (LodGrid::cellCenter).
    const int64_t num = (2 * int64_t(index[a]) + 1) * pc.edgeQuanta;
    center[a] = 2 * int64_t(pc.qmin[a]) + ((num + ((int64_t(1) << pc.cellLevel) >> 1)) >> pc.cellLevel);
  }
  uint best = kNotTaken, reached = 0;
  uint64_t bestDistance = 0ul, sum[3] = uint64_t[3](0ul, 0ul, 0ul);
  for (uint k = i; k < pc.count && (items.v[k].code >> cellShift) == cell; ++k) {
    if (taken.v[k] != kNotTaken) continue;
    const IndexItem p = items.v[k];
    const int64_t d[3] = int64_t[3](2 * int64_t(p.x) - center[0], 2 * int64_t(p.y) - center[1],
                                     2 * int64_t(p.z) - center[2]);
    const uint64_t distance = uint64_t(d[0] * d[0]) + uint64_t(d[1] * d[1]) + uint64_t(d[2] * d[2]);
    if (best == kNotTaken || distance < bestDistance) {
      best = k;
      bestDistance = distance;
    }
    sum[0] += p.rg & 0xFFFFu;
    sum[1] += p.rg >> 16;
    sum[2] += p.bIntensity & 0xFFFFu;
    ++reached;
  }
  if (reached == 0) return; // every point of the cell was taken above
  taken.v[best] = pc.level;
  const IndexItem p = items.v[best];
  uvec2 color = uvec2(p.rg, p.bIntensity & 0xFFFFu);
  if (pc.averageColors != 0 && reached > 1) {
    const uint64_t n = uint64_t(reached), rounding = n / 2;
    const uint r = uint((sum[0] + rounding) / n), g = uint((sum[1] + rounding) / n);
    const uint b = uint((sum[2] + rounding) / n);
    color = uvec2(r | g << 16, b);
  }
  Uvec2Array(pc.colors).v[best] = color;
}

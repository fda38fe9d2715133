#version 460
// One level's subsample, pass 3 of 3 (cloud/lod_index.h has the rules): each cell's first point marks
// the cell's choice (lod_index_cells, lod_index_best: among the cell's points no level above took, the
// one nearest the cell's center, the first in sorted order on a tie) taken at this level and gives it
// the average color of the points it stands for, then empties the cell's sums for the next level. Only
// in inner nodes: above the chunk's level every node is; from there on a node is inner when its cube
// holds more than leafPoints points: when the point leafPoints after its first is still in it. The node's
// first point is found by galloping back from the cell's (then a binary search), so that the many small
// nodes of the fine levels cost a few reads. The grid is isotropic (equal scales), so distances are
// exact integers.
#include "lod_index.inc.glsl"

layout(local_size_x = kIndexGroupSize) in;
layout(push_constant) uniform Push { IndexLevelPush pc; };

void main() {
  const uint i = linearInvocation(pc.groupsX, kIndexGroupSize);
  if (i >= pc.count || cellFirst(pc).v[i] != i) return; // not a cell's first point
  const uint reached = cellReached(pc).v[i], best = cellBest(pc).v[i];
  const uint64_t sum[3] = uint64_t[3](cellSums(pc).v[3 * i], cellSums(pc).v[3 * i + 1], cellSums(pc).v[3 * i + 2]);
  emptyCell(pc, i); // for the next level, whose cells start here too
  if (reached == 0) return; // every point of the cell was taken above
  if (pc.level >= pc.chunkLevel) {
    IndexItems items = IndexItems(pc.sorted);
    const uint nodeShift = 3 * (kIndexCodeLevels - pc.level);
    const uint64_t node = untaggedCode(items.v[i].code) >> nodeShift;
    uint lo = 0, hi = i; // items[hi] is in the node
    for (uint step = 1; step != 0 && step <= hi; step *= 2) {
      if ((untaggedCode(items.v[hi - step].code) >> nodeShift) < node) {
        lo = hi - step + 1;
        break;
      }
      hi -= step;
    }
    const uint first = firstAtLeast(items, lo, hi, nodeShift, node);
    const uint64_t probe = uint64_t(first) + pc.leafPoints;
    if (probe >= pc.count || (untaggedCode(items.v[uint(probe)].code) >> nodeShift) != node)
      return; // a leaf (at most leafPoints points): its points stay
  }
  UintArray(pc.taken).v[best] = pc.level;
  const IndexItem p = IndexItems(pc.sorted).v[best];
  uvec2 color = uvec2(p.rg, p.bIntensity & 0xFFFFu);
  if (pc.averageColors != 0 && reached > 1) {
    const uint64_t n = uint64_t(reached), rounding = n / 2;
    const uint r = uint((sum[0] + rounding) / n), g = uint((sum[1] + rounding) / n);
    const uint b = uint((sum[2] + rounding) / n);
    color = uvec2(r | g << 16, b);
  }
  Uvec2Array(pc.colors).v[best] = color;
}

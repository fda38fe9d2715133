// Buffers and helpers of the octree builder's index passes (lod_index_*.comp.glsl).
#include "common.inc.glsl"
#include "grid.inc.glsl"
#include "lod_index_shared.h"

layout(buffer_reference, std430, buffer_reference_align = 8) buffer IndexItems { IndexItem v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Uvec2Array { uvec2 v[]; };

// The point's code with the taken mark (bit 63) cleared.
uint64_t untaggedCode(uint64_t code) {
  return code & 0x7FFFFFFFFFFFFFFFul;
}

// Every third bit of v from bit 0 on, packed (the inverse of interleaving one axis of a Morton code).
uint compactBits3(uint64_t v) {
  v &= 0x1249249249249249ul;
  v = (v ^ (v >> 2)) & 0x30C30C30C30C30C3ul;
  v = (v ^ (v >> 4)) & 0xF00F00F00F00F00Ful;
  v = (v ^ (v >> 8)) & 0x00FF0000FF0000FFul;
  v = (v ^ (v >> 16)) & 0x00FF00000000FFFFul;
  v = (v ^ (v >> 32)) & 0x00000000001FFFFFul;
  return uint(v);
}

// The first point of this workgroup (kIndexGroupSize points a workgroup, on a grid groupsX wide).
uint groupBase(uint groupsX) {
  return (gl_WorkGroupID.y * groupsX + gl_WorkGroupID.x) * kIndexGroupSize;
}

// The cells' sums of a level pass (IndexLevelPush::cells), each an array of pc.count entries.
Uint64Array cellNearest(IndexLevelPush pc) { return Uint64Array(pc.cells); }
Uint64Array cellSums(IndexLevelPush pc) { return Uint64Array(pc.cells + 8ul * pc.count); } // r, g, b
UintArray cellReached(IndexLevelPush pc) { return UintArray(pc.cells + 32ul * pc.count); }
UintArray cellBest(IndexLevelPush pc) { return UintArray(pc.cells + 36ul * pc.count); }
UintArray cellFirst(IndexLevelPush pc) { return UintArray(pc.cells + 40ul * pc.count); }
UintArray equalCodesFlag(IndexLevelPush pc) { return UintArray(pc.cells + 44ul * pc.count); } // one uint

// A point's entries emptied: no distance, no sums, no choice (by the gather, and by a cell's first point
// after its level).
void emptyCell(IndexLevelPush pc, uint i) {
  cellNearest(pc).v[i] = ~0ul;
  for (int c = 0; c < 3; ++c)
    cellSums(pc).v[3 * i + c] = 0ul;
  cellReached(pc).v[i] = 0u;
  cellBest(pc).v[i] = kNotTaken;
}

// The first sorted point whose code >> shift is at least `key`, in [lo, hi) (hi if none).
uint firstAtLeast(IndexItems items, uint lo, uint hi, uint shift, uint64_t key) {
  while (lo < hi) {
    const uint mid = lo + (hi - lo) / 2;
    if ((untaggedCode(items.v[mid].code) >> shift) < key)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

// The shift that turns a code into its cell of the pass's grid.
uint cellShiftOf(IndexLevelPush pc) {
  return 3 * (kIndexCodeLevels - pc.cellLevel);
}

// The sorted point's cell of the pass's grid.
uint64_t cellOf(IndexLevelPush pc, uint i) {
  return untaggedCode(IndexItems(pc.sorted).v[i].code) >> cellShiftOf(pc);
}

// Twice the center of a grid cell, in quanta: 2 qmin + (2 i + 1) * E / 2^level, rounded
// (LodGrid::cellCenter).
i64vec3 cellCenter2(IndexLevelPush pc, uint64_t cell) {
  const uint index[3] = uint[3](compactBits3(cell >> 2), compactBits3(cell >> 1), compactBits3(cell));
  int64_t c[3];
  for (int a = 0; a < 3; ++a) {
    const int64_t num = (2 * int64_t(index[a]) + 1) * pc.edgeQuanta;
    c[a] = 2 * int64_t(pc.qmin[a]) + ((num + ((int64_t(1) << pc.cellLevel) >> 1)) >> pc.cellLevel);
  }
  return i64vec3(c[0], c[1], c[2]);
}

// The squared distance of a point (twice its coordinates) to twice a cell's center: exact integers.
uint64_t distanceTo(IndexItem p, i64vec3 center2) {
  const int64_t d[3] = int64_t[3](2 * int64_t(p.x) - center2.x, 2 * int64_t(p.y) - center2.y,
                                   2 * int64_t(p.z) - center2.z);
  return uint64_t(d[0] * d[0]) + uint64_t(d[1] * d[1]) + uint64_t(d[2] * d[2]);
}

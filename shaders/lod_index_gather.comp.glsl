#version 460
// The points in sorted order (sorted[i] = items[order[i]]), none taken yet, every cell's sums empty; the
// flag raised where two sorted points share a code (the CPU then puts them in canonical order).
#include "lod_index.inc.glsl"

layout(local_size_x = kIndexGroupSize) in;
layout(push_constant) uniform Push { IndexLevelPush pc; };

void main() {
  const uint i = linearInvocation(pc.groupsX, kIndexGroupSize);
  if (i >= pc.count) return;
  IndexItems(pc.sorted).v[i] = IndexItems(pc.items).v[UintArray(pc.order).v[i]];
  UintArray(pc.taken).v[i] = kNotTaken;
  emptyCell(pc, i);
  if (pc.keys != 0 && i > 0 &&
      untaggedCode(Uint64Array(pc.keys).v[i]) == untaggedCode(Uint64Array(pc.keys).v[i - 1]))
    atomicOr(equalCodesFlag(pc).v[0], 1u);
}

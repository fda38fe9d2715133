#version 460
// Radix sort, pass 1 of 3: each workgroup counts its tile's points per bucket of the code's bits
// [shift, shift + 8) and writes the counts bucket-major (histogram[bucket * tiles + tile]).
#include "lod_index.inc.glsl"

layout(local_size_x = kIndexGroupSize) in;
layout(push_constant) uniform Push { RadixPush pc; };

shared uint counts[256];

void main() {
  const uint t = gl_LocalInvocationIndex;
  const uint tile = gl_WorkGroupID.y * pc.groupsX + gl_WorkGroupID.x;
  counts[t] = 0;
  barrier();
  if (tile < pc.tiles) {
    const uint base = tile * kRadixTileItems;
    for (uint r = 0; r < kRadixItemsPerThread; ++r) {
      const uint i = base + r * kIndexGroupSize + t;
      if (i >= pc.count) break;
      const uint64_t key = pc.items != 0 ? IndexItems(pc.items).v[i].code : Uint64Array(pc.keysIn).v[i];
      atomicAdd(counts[uint(untaggedCode(key) >> pc.shift) & 255u], 1u);
    }
  }
  barrier();
  if (tile < pc.tiles) UintArray(pc.histogram).v[t * pc.tiles + tile] = counts[t];
}

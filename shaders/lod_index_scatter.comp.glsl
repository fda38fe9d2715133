#version 460
// Radix sort, pass 3 of 3: each workgroup moves its tile's (code, index) pairs to their buckets' places,
// keeping their order within a bucket (the sort is stable, so passes from the low bits up sort by the
// whole code). The tile goes in rounds of 256 points; a point's rank among the round's points of its
// bucket is counted over the threads before it.
#include "lod_index.inc.glsl"

layout(local_size_x = kIndexGroupSize) in;
layout(push_constant) uniform Push { RadixPush pc; };

shared uint offsets[256];
shared uint buckets[kIndexGroupSize];

void main() {
  const uint t = gl_LocalInvocationIndex;
  const uint tile = gl_WorkGroupID.y * pc.groupsX + gl_WorkGroupID.x;
  if (tile >= pc.tiles) return; // the whole workgroup: no barrier is skipped by part of it
  offsets[t] = UintArray(pc.histogram).v[t * pc.tiles + tile];
  barrier();
  const uint base = tile * kRadixTileItems;
  for (uint r = 0; r < kRadixItemsPerThread; ++r) {
    const uint i = base + r * kIndexGroupSize + t;
    const bool valid = i < pc.count;
    uint64_t key = 0;
    uint value = 0, bucket = 256u;
    if (valid) {
      key = pc.items != 0 ? IndexItems(pc.items).v[i].code : Uint64Array(pc.keysIn).v[i];
      value = pc.items != 0 ? i : UintArray(pc.valuesIn).v[i];
      bucket = uint(untaggedCode(key) >> pc.shift) & 255u;
    }
    buckets[t] = bucket;
    barrier();
    uint rank = 0;
    for (uint j = 0; j < t; ++j)
      rank += buckets[j] == bucket ? 1u : 0u;
    if (valid) {
      const uint at = offsets[bucket] + rank;
      Uint64Array(pc.keysOut).v[at] = key;
      UintArray(pc.valuesOut).v[at] = value;
    }
    barrier();
    if (valid) atomicAdd(offsets[bucket], 1u);
    barrier();
  }
}

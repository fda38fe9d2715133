#version 460
// Radix sort, pass 2 of 3: the exclusive prefix sum of the bucket-major histogram, in place, by one
// workgroup (each thread a contiguous run, then the runs' sums). Afterwards histogram[b * tiles + t] is
// where tile t's first point of bucket b goes.
#include "lod_index.inc.glsl"

layout(local_size_x = kIndexGroupSize) in;
layout(push_constant) uniform Push { RadixPush pc; };

shared uint sums[kIndexGroupSize];

void main() {
  const uint t = gl_LocalInvocationIndex;
  const uint total = 256u * pc.tiles;
  const uint per = (total + kIndexGroupSize - 1) / kIndexGroupSize;
  const uint begin = min(t * per, total), end = min(begin + per, total);
  UintArray h = UintArray(pc.histogram);
  uint sum = 0;
  for (uint i = begin; i < end; ++i)
    sum += h.v[i];
  sums[t] = sum;
  barrier();
  if (t == 0) {
    uint running = 0;
    for (uint k = 0; k < kIndexGroupSize; ++k) {
      const uint v = sums[k];
      sums[k] = running;
      running += v;
    }
  }
  barrier();
  uint running = sums[t];
  for (uint i = begin; i < end; ++i) {
    const uint v = h.v[i];
    h.v[i] = running;
    running += v;
  }
}

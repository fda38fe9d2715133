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

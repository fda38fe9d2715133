#version 460
// Framebuffer of 64-bit words -> RGBA8 image (low 32 bits are the color), background where empty; then
// optionally clears the word so the next frame needs no separate clear pass.
#include "common.inc.glsl"

layout(local_size_x = kPixelGroupSize) in;
layout(push_constant) uniform Push { ResolvePush pc; };

void main() {
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * kPixelGroupSize;
  if (i >= pc.width * pc.height) return;
  Uint64Array fb = Uint64Array(pc.framebuffer);
  uint64_t word = fb.v[i];
  UintArray(pc.image).v[i] = word == kEmptyPixel ? pc.background : uint(word & 0xFFFFFFFFul);
  if (pc.clearAfter != 0) fb.v[i] = kEmptyPixel;
}

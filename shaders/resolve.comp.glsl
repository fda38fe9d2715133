#version 460
// Framebuffer of 64-bit words -> RGBA8 image: the low 32 bits are the color of the closest point; the
// background where no point landed.
#include "common.inc.glsl"

layout(local_size_x = kPixelGroupSize) in;
layout(push_constant) uniform Push { ResolvePush pc; };

void main() {
  uint i = linearInvocation(pc.groupsX, kPixelGroupSize);
  if (i >= pc.width * pc.height) return;
  uint64_t word = Uint64Array(pc.framebuffer).v[i];
  UintArray(pc.image).v[i] = word == kEmptyPixel ? pc.background : uint(word & 0xFFFFFFFFul);
}

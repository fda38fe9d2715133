#version 460
// The 2019 method (Schuetz, Kerbl, Wimmer, "Rendering Point Clouds with Compute Shaders"): one thread
// per point, one 64-bit atomicMin of (depth << 32 | color) into the framebuffer. The min keeps the closest
// point whatever the order threads run in, so the image is deterministic.
#include "common.inc.glsl"
#include "project.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };

void main() {
  uint i = linearInvocation(pc.groupsX, kPointGroupSize);
  if (i >= pc.pointCount) return;
  FloatArray pos = FloatArray(pc.positions);
  vec3 p = vec3(pos.v[3 * i], pos.v[3 * i + 1], pos.v[3 * i + 2]);
  uint pixel, depthBits;
  if (!projectPoint(pc.viewProj, p, pc.width, pc.height, pc.nearW, pixel, depthBits)) return;
  uint color = UintArray(pc.colors).v[i];
  uint64_t word = (uint64_t(depthBits) << 32) | uint64_t(color);
  atomicMin(Uint64Array(pc.framebuffer).v[pixel], word);
}

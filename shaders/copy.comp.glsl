#version 460
// Copy bandwidth with the shader cores: each invocation moves one 16-byte vector. On NVIDIA,
// vkCmdCopyBuffer runs on a copy engine far below HBM bandwidth (an H200 measured 851 GB/s that way), so
// this is the physical limit a point rasterizer's loads can approach.
#include "common.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = 256) in;
layout(push_constant) uniform Push { CopyPush pc; };
// Written, so not common.inc.glsl's readonly Uvec4Array.
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Uvec4Words { uvec4 v[]; };

void main() {
  uint i = linearInvocation(pc.groupsX, 256);
  if (i < pc.count) Uvec4Words(pc.destination).v[i] = Uvec4Array(pc.source).v[i];
}

#version 460
// sphere-compute, pass 4: the chunks of large spheres that the cull pass (3) left to draw, one chunk (a
// screen tile or a band of box rows, clipped to the sphere's box) per workgroup iteration, one pixel per
// thread. A fixed grid of workgroups strides over the list (the count is known only on the GPU;
// pc.groupsX is the number of workgroups), so no indirect dispatch is needed.
#include "sphere_raster.inc.glsl"

layout(local_size_x = kSphereChunkPixels) in;
layout(push_constant) uniform Push { SpherePush pc; };

// This invocation's pixel of the chunk (row-major over the chunk's width), if the chunk has it.
void drawChunkPixel(uint index, ivec4 chunk) {
  int width = chunk.z - chunk.x + 1;
  ivec2 p = chunk.xy + ivec2(int(gl_LocalInvocationIndex) % width, int(gl_LocalInvocationIndex) / width);
  if (p.y > chunk.w) return;
  countWork(0);
  Sphere s = sphereByIndex(index);
  vec3 center;
  // Always true for a listed sphere (the same call as in pass 1).
  if (viewSphere(s, center)) coverPixel(center, s.radius, index, p);
}

void main() {
  frame = SphereFrameRef(pc.frame).f;
  SphereChunks list = SphereChunks(frame.chunks);
  uint total = list.drawn;
  for (uint e = gl_WorkGroupID.x; e < total; e += pc.groupsX) {
    uvec4 entry = list.entries[UintArray(frame.drawnChunks).v[e]];
    drawChunkPixel(entry.x, unpackChunk(entry.yz));
  }
}

#version 460
// sphere-compute, pass 3: the chunks of large spheres listed by pass 1, one chunk (a screen tile clipped to
// the sphere's box) per workgroup iteration, one pixel per thread. A fixed grid of workgroups strides over
// the list (the count is known only on the GPU; pc.groupsX is the number of workgroups), so no indirect
// dispatch is needed. A chunk whose sphere's front lies behind its tile's depth bound (pass 2) is skipped
// whole after one comparison, before the sphere is even read: the overdraw of a close-up, where most
// large spheres are hidden behind nearer ones, costs a few loads per chunk instead of a ray test per pixel.
#include "sphere_raster.inc.glsl"

layout(local_size_x = kSphereChunkPixels) in;
layout(push_constant) uniform Push { SpherePush pc; };

// This invocation's pixel of the chunk, if the chunk has it.
void drawChunkPixel(uint index, ivec4 chunk) {
  ivec2 p = chunk.xy + ivec2(gl_LocalInvocationIndex % kSphereTileSide,
                             gl_LocalInvocationIndex / kSphereTileSide);
  if (p.x > chunk.z || p.y > chunk.w) return;
  countWork(0);
  Sphere s = sphereByIndex(index);
  vec3 center;
  // Always true for a listed sphere (the same call as in pass 1).
  if (viewSphere(s, center)) coverPixel(center, s.radius, index, p);
}

void main() {
  frame = SphereFrameRef(pc.frame).f;
  SphereChunks list = SphereChunks(frame.chunks);
  uint total = uint(min(list.count, uint64_t(frame.chunkCapacity)));
  for (uint e = gl_WorkGroupID.x; e < total; e += pc.groupsX) {
    uvec4 entry = list.entries[e];
    ivec4 chunk = unpackChunk(entry.yz);
    if (TILE_BOUND != 0 && entry.w > UintArray(frame.tileBounds).v[tileOf(chunk.xy)]) {
      if (gl_LocalInvocationIndex == 0) countWork(3);
    } else {
      drawChunkPixel(entry.x, chunk);
    }
  }
}

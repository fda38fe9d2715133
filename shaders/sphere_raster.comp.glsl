#version 460
// sphere-compute, pass 1: one thread per sphere of a part. Culls the sphere (near plane, frustum, bad
// values), then either ray-tests its whole pixel box itself (at most kSphereSmallPixels pixels: most
// spheres of a large set) or cuts the box into chunks of 256 pixels appended to the large-sphere list for
// sphere_raster_large.comp, so that a sphere filling the screen is spread over many workgroups instead
// of serializing a frame on one thread.
//
// The list never overflows silently: chunks past its capacity are drawn here, by the sphere's own thread
// (slow but exact), and the sphere is counted in `spilled`. Chunks are reserved with one 64-bit atomicAdd
// per sphere: a compare-and-swap loop that stops at the capacity would serialize every large sphere of
// the frame on one word (measured: seconds for a close-up of 10 M particles on an H200), and 64 bits
// cannot wrap.
#include "sphere_raster.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kSphereGroupSize) in;
layout(push_constant) uniform Push { SpherePush pc; };

void main() {
  uint local = linearInvocation(pc.groupsX, kSphereGroupSize);
  if (local >= pc.count) return;
  frame = SphereFrameRef(pc.frame).f;
  Sphere s = loadSphere(pc.particles, pc.count, local);
  vec3 center;
  if (!viewSphere(s, center)) return;
  ivec4 box = spherePixelBox(center, s.radius);
  if (box.z < box.x || box.w < box.y) return;
  uint index = pc.first + local;
  uvec2 size = uvec2(box.zw - box.xy + 1);
  uint pixels = size.x * size.y;
  if (pixels <= kSphereSmallPixels) {
    coverBox(center, s.radius, index, box);
    return;
  }
  uint n = (pixels + kSphereChunkPixels - 1) / kSphereChunkPixels;
  SphereChunks list = SphereChunks(frame.chunks);
  uint64_t at = atomicAdd(list.count, uint64_t(n));
  uvec4 entry = uvec4(index, uint(box.x) | (uint(box.y) << 16), size.x | (size.y << 16), 0);
  for (uint k = 0; k < n; ++k) {
    entry.w = k * kSphereChunkPixels;
    if (at + k < uint64_t(frame.chunkCapacity))
      list.entries[uint(at) + k] = entry;
    else
      coverChunk(center, s.radius, index, box, entry.w);
  }
  if (at + n > uint64_t(frame.chunkCapacity)) atomicAdd(list.spilled, 1u);
}

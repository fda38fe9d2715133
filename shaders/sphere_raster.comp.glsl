#version 460
// sphere-compute, pass 1: one thread per sphere of a part. Culls the sphere (near plane, frustum, bad
// values), then either ray-tests its whole pixel box itself (at most kSphereSmallPixels pixels: most
// spheres of a large set) or cuts the box along the screen's 16 x 16 tiles into chunks appended to the
// large-sphere list for sphere_tile_bound.comp and sphere_raster_large.comp, so that a sphere filling the
// screen is spread over many workgroups instead of serializing a frame on one thread.
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
  if (size.x * size.y <= kSphereSmallPixels) {
    coverBox(center, s.radius, index, box);
    return;
  }
  ivec2 firstTile = box.xy >> int(kSphereTileShift);
  uint tilesX = uint((box.z >> int(kSphereTileShift)) - firstTile.x + 1);
  uint n = tilesX * uint((box.w >> int(kSphereTileShift)) - firstTile.y + 1);
  SphereChunks list = SphereChunks(frame.chunks);
  uint64_t at = atomicAdd(list.count, uint64_t(n));
  uint front = floatBitsToUint(-center.z - s.radius);
  for (uint k = 0; k < n; ++k) {
    ivec4 tile = tilePixels(uvec2(firstTile) + uvec2(k % tilesX, k / tilesX));
    ivec4 chunk = ivec4(max(tile.xy, box.xy), min(tile.zw, box.zw));
    if (at + k < uint64_t(frame.chunkCapacity))
      list.entries[uint(at) + k] = uvec4(index, packChunk(chunk), front);
    else
      coverBox(center, s.radius, index, chunk);
  }
  if (at + n > uint64_t(frame.chunkCapacity)) atomicAdd(list.spilled, 1u);
}

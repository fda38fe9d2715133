#version 460
// sphere-compute, pass 2: the tile depth bounds, one thread per chunk of the large-sphere list, before any
// chunk is drawn. A chunk that is its whole tile (clipped to the image) and whose sphere covers the tile's
// four corner pixel centers lowers the tile's bound to the largest of the four hit depths, so that pass 3
// (the cull) drops every chunk of a sphere whose front lies behind it. Why that is exact:
//   - the directions that pass through a sphere form a convex cone (narrowed here to those passing at
//     least r^2 / 256 inside, so that rounding cannot turn an inner pixel into a miss), and the pixel
//     centers of the tile are convex combinations of its corners on the plane z = -1: every one is hit;
//   - over that cone 1 / (nearest-hit depth) is concave (a projective map of the convex sphere), so the
//     nearest-hit depth is largest at a corner;
//   - the bound is widened by 2048 units in the last place (2^-12 to 2^-11 of itself, an integer add on
//     its bits) against the rounding of both spheres' depths, so a skipped sphere would have lost every
//     pixel of the tile: the image is the same with and without the bounds.
// The spilled chunks (drawn by pass 1) set no bound; a tile without a bound skips nothing.
#include "sphere_raster.inc.glsl"

layout(local_size_x = kSphereChunkPixels) in;
layout(push_constant) uniform Push { SpherePush pc; };

// The largest nearest-hit depth over the rays through the four corners of pixel rectangle r, or 0 if a
// corner ray does not pass well inside the sphere.
float coveredDepth(vec3 center, float radius, ivec4 r) {
  float deepest = 0.0;
  for (uint k = 0; k < 4; ++k) {
    vec2 corner = vec2((k & 1u) != 0 ? r.z : r.x, (k & 2u) != 0 ? r.w : r.y) + 0.5;
    float depth;
    if (!intersectSphereWithin(center, radius, sphereRay(frame.pixelToRay, corner),
                               radius * radius * (1.0 / 256.0), depth))
      return 0.0;
    deepest = max(deepest, depth);
  }
  return deepest;
}

void main() {
  frame = SphereFrameRef(pc.frame).f;
  SphereChunks list = SphereChunks(frame.chunks);
  uint total = uint(min(list.count, uint64_t(frame.chunkCapacity)));
  uint stride = pc.groupsX * kSphereChunkPixels;
  for (uint e = gl_GlobalInvocationID.x; e < total; e += stride) {
    uvec4 entry = list.entries[e];
    ivec4 chunk = unpackChunk(entry.yz);
    if (chunk != tilePixels(uvec2(chunk.xy) >> kSphereTileShift)) continue;
    Sphere s = sphereByIndex(entry.x);
    vec3 center;
    // Always true for a listed sphere (the same call as in pass 1).
    if (!viewSphere(s, center)) continue;
    float depth = coveredDepth(center, s.radius, chunk);
    if (depth > 0.0)
      atomicMin(UintArray(frame.tileBounds).v[tileOf(chunk.xy)],
                floatBitsToUint(depth) + 2048u);
  }
}

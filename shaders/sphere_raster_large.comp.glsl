#version 460
// sphere-compute, pass 3: the chunks of large spheres listed by pass 1, one chunk (a screen tile or a band
// of box rows, clipped to the sphere's box) per workgroup iteration, one pixel per thread. A fixed grid of
// workgroups strides over the list (the count is known only on the GPU; pc.groupsX is the number of
// workgroups), so no indirect dispatch is needed. A chunk whose sphere's front lies behind the depth bound
// (pass 2) of every tile it touches is skipped whole, before the sphere is even read: the overdraw of a
// close-up, where most large spheres are hidden behind nearer ones, costs a few loads per chunk instead
// of a ray test per pixel.
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

// Whether the chunk lies behind the depth bound of every tile it touches (one for a tile chunk, a few for a
// band of box rows): then the sphere loses each of its pixels. Uniform over the workgroup; stops at the
// first tile where the sphere could still win.
bool hidden(uvec4 entry, ivec4 chunk) {
  if (TILE_BOUND == 0) return false;
  ivec4 tiles = chunk >> int(kSphereTileShift);
  if (any(greaterThan(tiles.zw - tiles.xy, ivec2(1)))) return false;
  UintArray bounds = UintArray(frame.tileBounds);
  uint row0 = uint(tiles.y) * frame.tilesX, row1 = uint(tiles.w) * frame.tilesX;
  uint bound = max(max(bounds.v[row0 + uint(tiles.x)], bounds.v[row0 + uint(tiles.z)]),
                   max(bounds.v[row1 + uint(tiles.x)], bounds.v[row1 + uint(tiles.z)]));
  return entry.w > bound;
}

void main() {
  frame = SphereFrameRef(pc.frame).f;
  SphereChunks list = SphereChunks(frame.chunks);
  uint total = uint(min(list.count, uint64_t(frame.chunkCapacity)));
  for (uint e = gl_WorkGroupID.x; e < total; e += pc.groupsX) {
    uvec4 entry = list.entries[e];
    ivec4 chunk = unpackChunk(entry.yz);
    if (hidden(entry, chunk)) {
      if (gl_LocalInvocationIndex == 0) countWork(3);
    } else {
      drawChunkPixel(entry.x, chunk);
    }
  }
}

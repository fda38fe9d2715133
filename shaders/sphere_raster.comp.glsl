#version 460
// sphere-compute, pass 1: one thread per sphere of a part. Culls the sphere (near plane, frustum, bad
// values), then either ray-tests its whole pixel box itself (at most kSphereSmallPixels pixels: most
// spheres of a large set) or cuts the box into chunks of at most 256 pixels (screen tiles, or bands of box
// rows) appended to the large-sphere list for passes 2-4 (sphere_tile_bound, sphere_chunk_cull and
// sphere_raster_large.comp), so
// that a sphere filling the screen is spread over many workgroups instead of serializing a frame on one
// thread.
//
// The list never overflows silently: chunks past its capacity are drawn here, by the sphere's own thread
// (slow but exact), and the sphere is counted in `spilled`. Chunks are reserved with one 64-bit atomicAdd
// per sphere: a compare-and-swap loop that stops at the capacity would serialize every large sphere of
// the frame on one word (measured: seconds for a close-up of 10 M particles on an H200), and 64 bits
// cannot wrap.
#include "sphere_raster.inc.glsl"
#include "grid.inc.glsl"

// LIST: 0 = every sphere of the part (occlusion culling off); 1 = the batches of the SphereBatchList at
// pc.particles, whatever part each is in, a fixed grid of pc.groupsX workgroups striding over the list
// (one workgroup is one batch).
layout(constant_id = 6) const uint LIST = 0;

layout(local_size_x = kSphereGroupSize) in;
layout(push_constant) uniform Push { SpherePush pc; };

// Sphere `local` of the part at `part` (`count` spheres, the first of global index `first`).
void drawSphere(uint64_t part, uint count, uint first, uint local) {
  Sphere s = loadSphere(part, count, local);
  vec3 center;
  if (!viewSphere(s, center)) return;
  ivec4 box = spherePixelBox(center, s.radius);
  if (box.z < box.x || box.w < box.y) return;
  uint index = first + local;
  uvec2 size = uvec2(box.zw - box.xy + 1);
  if (size.x * size.y <= kSphereSmallPixels) {
    coverBox(center, s.radius, index, box);
    return;
  }
  // The chunks are the cells of a grid clipped to the box: screen tiles for a sphere much larger than a
  // tile (their depth bounds skip most of a close-up's hidden chunks), bands of whole box rows for a
  // mid-size one (a box just above the small limit straddles up to four tiles but fills one band).
  ivec2 origin;
  uvec2 step;
  if (size.x * size.y > TILE_CUT_PIXELS || size.x > kSphereChunkPixels) {
    origin = (box.xy >> int(kSphereTileShift)) << int(kSphereTileShift);
    step = uvec2(kSphereTileSide);
  } else {
    origin = box.xy;
    step = uvec2(size.x, kSphereChunkPixels / size.x);
  }
  uvec2 cells = uvec2(box.zw - origin) / step + 1;
  uint n = cells.x * cells.y;
  SphereChunks list = SphereChunks(frame.chunks);
  uint64_t at = atomicAdd(list.count, uint64_t(n));
  uint front = floatBitsToUint(-center.z - s.radius);
  for (uint k = 0; k < n; ++k) {
    ivec2 lo = origin + ivec2(uvec2(k % cells.x, k / cells.x) * step);
    ivec4 chunk = ivec4(max(lo, box.xy), min(lo + ivec2(step) - 1, box.zw));
    if (at + k < uint64_t(frame.chunkCapacity))
      list.entries[uint(at) + k] = uvec4(index, packChunk(chunk), front);
    else
      coverBox(center, s.radius, index, chunk);
  }
  if (at + n > uint64_t(frame.chunkCapacity)) atomicAdd(list.spilled, 1u);
}

void main() {
  frame = SphereFrameRef(pc.frame).f;
  if (LIST != 0) {
    SphereBatchList batches = SphereBatchList(pc.particles);
    uint total = batches.count;
    for (uint e = gl_WorkGroupID.x; e < total; e += pc.groupsX) {
      uint batch = batches.entries[e];
      uint part = batch / frame.batchesPerPart;
      uint local = (batch - part * frame.batchesPerPart) * kSphereBatchSize + gl_LocalInvocationIndex;
      SpherePartRef ref = PartTable(frame.parts).v[part];
      if (local < ref.count) drawSphere(ref.address, ref.count, part * frame.partCapacity, local);
    }
    return;
  }
  uint local = linearInvocation(pc.groupsX, kSphereGroupSize);
  if (local >= pc.count) return;
  drawSphere(pc.particles, pc.count, pc.first, local);
}

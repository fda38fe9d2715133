#version 460
// sphere-compute's occlusion culling, after the first draw of a frame: the depth pyramid the batch cull
// tests against, one workgroup per 16 x 16-pixel screen tile. A tile's value is the deepest visibility
// word it holds now (an empty pixel: ones, so nothing is culled there), lowered to the tile's depth bound
// from the large-sphere chunks listed so far (sphere_tile_bound.comp: chunks drawn later in the frame, whose
// spheres surely cover the tile). Pixels only ever get nearer, so every pixel center of the tile ends the
// frame at that depth or nearer. A coarse cell (kSphereCoarseTiles^2 tiles) holds the deepest of its
// tiles; a fine cell (4 x 4 pixels) the deepest of its pixels, lowered to the tile's bound too.
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "sphere_raster.inc.glsl"

layout(local_size_x = kSphereChunkPixels) in;
layout(push_constant) uniform Push { SpherePush pc; };

shared uint deepest;
shared uint fine[kSphereFinePerTile * kSphereFinePerTile];

void main() {
  frame = SphereFrameRef(pc.frame).f;
  uint lane = gl_LocalInvocationIndex;
  if (lane == 0) deepest = 0u;
  if (lane < kSphereFinePerTile * kSphereFinePerTile) fine[lane] = 0u;
  barrier();
  uvec2 tile = gl_WorkGroupID.xy;
  uvec2 at = uvec2(lane % kSphereTileSide, lane / kSphereTileSide);
  ivec2 p = ivec2(tile << kSphereTileShift) + ivec2(at);
  uint depth = 0u;
  if (p.x < int(frame.width) && p.y < int(frame.height))
    depth = uint(Uint64Array(frame.framebuffer).v[uint(p.y) * frame.width + uint(p.x)] >> 32);
  atomicMax(fine[(at.y >> kSphereFineShift) * kSphereFinePerTile + (at.x >> kSphereFineShift)], depth);
  depth = subgroupMax(depth);
  if (subgroupElect()) atomicMax(deepest, depth);
  barrier();
  uint t = tile.y * frame.tilesX + tile.x;
  uint tileBound = UintArray(frame.tileBounds).v[t];
  UintArray hiz = UintArray(frame.hiz);
  if (lane < kSphereFinePerTile * kSphereFinePerTile) {
    uvec2 cell = tile * kSphereFinePerTile + uvec2(lane % kSphereFinePerTile, lane / kSphereFinePerTile);
    hiz.v[frame.fineOffset + cell.y * frame.tilesX * kSphereFinePerTile + cell.x] = min(fine[lane], tileBound);
  }
  if (lane != 0) return;
  uint bound = min(deepest, tileBound);
  hiz.v[t] = bound;
  uvec2 cell = tile >> kSphereCoarseShift;
  atomicMax(hiz.v[frame.coarseOffset + cell.y * frame.coarseX + cell.x], bound);
}

#version 460
// sphere-compute's occlusion culling, after the first draw of a frame: the depth pyramid the batch cull
// tests against, one workgroup per 16 x 16-pixel screen tile. A tile's value is the deepest visibility
// word it holds now (an empty pixel: ones, so nothing is culled there), lowered to the tile's depth bound
// from the large-sphere chunks listed so far (sphere_tile_bound.comp: chunks drawn later in the frame, whose
// spheres surely cover the tile). Pixels only ever get nearer, so every pixel center of the tile ends the
// frame at that depth or nearer. A coarse cell (kSphereCoarseTiles^2 tiles) holds the deepest of its tiles.
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "sphere_raster.inc.glsl"

layout(local_size_x = kSphereChunkPixels) in;
layout(push_constant) uniform Push { SpherePush pc; };

shared uint deepest;

void main() {
  frame = SphereFrameRef(pc.frame).f;
  if (gl_LocalInvocationIndex == 0) deepest = 0u;
  barrier();
  uvec2 tile = gl_WorkGroupID.xy;
  ivec2 p = ivec2(tile << kSphereTileShift) +
            ivec2(gl_LocalInvocationIndex % kSphereTileSide, gl_LocalInvocationIndex / kSphereTileSide);
  uint depth = 0u;
  if (p.x < int(frame.width) && p.y < int(frame.height))
    depth = uint(Uint64Array(frame.framebuffer).v[uint(p.y) * frame.width + uint(p.x)] >> 32);
  depth = subgroupMax(depth);
  if (subgroupElect()) atomicMax(deepest, depth);
  barrier();
  if (gl_LocalInvocationIndex != 0) return;
  uint t = tile.y * frame.tilesX + tile.x;
  uint bound = min(deepest, UintArray(frame.tileBounds).v[t]);
  UintArray hiz = UintArray(frame.hiz);
  hiz.v[t] = bound;
  uvec2 cell = tile >> kSphereCoarseShift;
  atomicMax(hiz.v[frame.coarseOffset + cell.y * frame.coarseX + cell.x], bound);
}

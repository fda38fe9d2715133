#version 460
// sphere-compute's occlusion culling, between a frame's two draws: one thread per batch. A batch's bounds
// (radii included) are projected; if the nearest of their eight corners lies behind the depth pyramid
// (sphere_hiz.comp) over every pixel the bounds may cover, none of its spheres can win a pixel: each would
// be strictly deeper than what that pixel ends the frame with. The test reads at most
// kSphereBatchTestCells fine cells, else as many tiles, else as many coarse cells, else it keeps the batch. A batch that may show
// is appended to the next frame's first list (at pc.particles), and also to this frame's second list if
// the first draw did not take it; every batch's flag becomes whether it may show.
#extension GL_KHR_shader_subgroup_ballot : require
#include "sphere_raster.inc.glsl"
#include "grid.inc.glsl"

layout(local_size_x = kSphereGroupSize) in;
layout(push_constant) uniform Push { SpherePush pc; };

// The deepest pyramid value over cells (x0, y0, x1, y1) of the level at `base` with `row` cells per row
// (at most kSphereBatchTestCells cells).
uint deepestOver(uint base, uint row, uvec4 cells) {
  UintArray hiz = UintArray(frame.hiz);
  uint deepest = 0u;
  uint width = cells.z - cells.x + 1;
  uint n = width * (cells.w - cells.y + 1);
  for (uint k = 0; k < n; ++k)
    deepest = max(deepest, hiz.v[base + (cells.y + k / width) * row + cells.x + k % width]);
  return deepest;
}

// Whether any sphere of a batch with bounds [lo, hi] may win a pixel this frame.
bool batchMayShow(vec3 lo, vec3 hi) {
  if (any(greaterThan(lo, hi))) return false; // no valid sphere
  float nearest = 3.0e38;
  vec2 first = vec2(3.0e38), last = vec2(-3.0e38);
  for (uint k = 0; k < 8; ++k) {
    vec3 corner = vec3((k & 1u) != 0 ? hi.x : lo.x, (k & 2u) != 0 ? hi.y : lo.y, (k & 4u) != 0 ? hi.z : lo.z);
    vec3 v = (frame.view * vec4(corner, 1.0)).xyz;
    float depth = -v.z;
    // Bounds reaching the near plane are not tested (NaN fails the comparison too).
    if (!(depth > frame.nearW)) return true;
    nearest = min(nearest, depth);
    vec2 pixel = rayPixel(frame.pixelToRay, v.xy / depth);
    first = min(first, pixel);
    last = max(last, pixel);
  }
  // Pixels whose centers p + 0.5 lie within the projected bounds, widened by half a pixel for rounding
  // (the projection of the box contains that of every sphere in it).
  vec2 size = vec2(frame.width, frame.height);
  ivec2 p0 = ivec2(clamp(ceil(first - 1.0), vec2(0.0), size));
  ivec2 p1 = ivec2(clamp(floor(last), vec2(-1.0), size - 1.0));
  if (any(lessThan(p1, p0))) return false; // outside the image
  // The finest level whose cells over the pixels number at most kSphereBatchTestCells.
  uint level = frame.fineOffset, row = frame.tilesX * kSphereFinePerTile;
  uvec4 cells = uvec4(p0, p1) >> kSphereFineShift;
  if ((cells.z - cells.x + 1) * (cells.w - cells.y + 1) > kSphereBatchTestCells) {
    level = 0u;
    row = frame.tilesX;
    cells = uvec4(p0, p1) >> kSphereTileShift;
  }
  if ((cells.z - cells.x + 1) * (cells.w - cells.y + 1) > kSphereBatchTestCells) {
    level = frame.coarseOffset;
    row = frame.coarseX;
    cells = uvec4(p0, p1) >> (kSphereTileShift + kSphereCoarseShift);
    if ((cells.z - cells.x + 1) * (cells.w - cells.y + 1) > kSphereBatchTestCells) return true;
  }
  // Against the rounding of corner and sphere transforms: 1024 units in the last place (~1.2e-4 of the
  // depth) nearer.
  uint bits = floatBitsToUint(nearest);
  return bits <= 1024u || bits - 1024u <= deepestOver(level, row, cells);
}

// Appends `batch` to the list where `append` holds: one atomic per subgroup. Every lane must call it.
void appendTo(SphereBatchList list, bool append, uint batch) {
  uvec4 ballot = subgroupBallot(append);
  uint count = subgroupBallotBitCount(ballot);
  uint at = 0;
  if (count > 0 && subgroupElect()) at = atomicAdd(list.count, count);
  at = subgroupBroadcastFirst(at);
  if (append) list.entries[at + subgroupBallotExclusiveBitCount(ballot)] = batch;
}

void main() {
  frame = SphereFrameRef(pc.frame).f;
  uint batch = linearInvocation(pc.groupsX, kSphereGroupSize);
  bool show = false, drawn = false;
  if (batch < frame.batches) {
    UintArray flags = UintArray(frame.batchFlags);
    drawn = flags.v[batch] != 0u;
    Vec4Array bounds = Vec4Array(frame.batchBounds);
    show = batchMayShow(bounds.v[2 * batch].xyz, bounds.v[2 * batch + 1].xyz);
    if (show != drawn) flags.v[batch] = show ? 1u : 0u;
  }
  appendTo(SphereBatchList(pc.particles), show, batch);
  appendTo(SphereBatchList(frame.batchList), show && !drawn, batch);
}

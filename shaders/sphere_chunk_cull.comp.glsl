#version 460
// sphere-compute, pass 3: the cull of the large-sphere list, one thread per listed chunk, after the tile
// depth bounds (pass 2) and before the draw (pass 4). A chunk behind the bounds of the tiles it touches is
// dropped here; the list index of every other chunk is appended to SphereFrame::drawnChunks, which the
// draw pass iterates. In a close-up most chunks are hidden, and a dropped chunk costs one thread's
// coalesced 16-byte read here instead of a serial iteration of a 256-thread workgroup there. One atomic
// per subgroup reserves the survivors' slots.
#extension GL_KHR_shader_subgroup_ballot : require
#include "sphere_raster.inc.glsl"

layout(local_size_x = kSphereChunkPixels) in;
layout(push_constant) uniform Push { SpherePush pc; };

void main() {
  frame = SphereFrameRef(pc.frame).f;
  SphereChunks list = SphereChunks(frame.chunks);
  uint total = uint(min(list.count, uint64_t(frame.chunkCapacity)));
  uint stride = pc.groupsX * kSphereChunkPixels;
  // The loop bound is uniform over the workgroup, so every lane of a subgroup reaches the ballot.
  for (uint first = gl_WorkGroupID.x * kSphereChunkPixels; first < total; first += stride) {
    uint e = first + gl_LocalInvocationIndex;
    bool draw = e < total;
    if (draw && chunkHidden(list.entries[e])) {
      countWork(3);
      draw = false;
    }
    uvec4 ballot = subgroupBallot(draw);
    uint at = 0;
    if (subgroupElect()) at = atomicAdd(list.drawn, subgroupBallotBitCount(ballot));
    at = subgroupBroadcastFirst(at);
    if (draw) UintArray(frame.drawnChunks).v[at + subgroupBallotExclusiveBitCount(ballot)] = e;
  }
}

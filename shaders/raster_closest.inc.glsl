// The closest-point family of the 2021 paper (Schuetz, Kerbl, Wimmer, "Rendering Point Clouds with
// Compute Shaders and Vertex Order Optimization"), one thread per point. All variants write the same
// framebuffer: the minimum of (depth << 32 | color) per pixel, whatever order points arrive in.
//   EARLY_Z   read the pixel first and skip the atomic if the point is not closer (most points in dense
//             views are hidden, and a read is cheaper than an atomic)
//   REDUCE    0: none
//             1: subgroup reduction: if the whole subgroup hits one pixel, one atomic of the subgroup
//                minimum; otherwise neighbouring pairs that share a pixel combine first (clustered)
//             2: dedup from ballots: one atomic per distinct pixel of the subgroup (portable)
//   JUST_SET  plain stores without any depth test: a speed reference, not a correct image
//   DEPTH_ONLY the payload is 0 and colors are not read (the depth pass of HQS)
// DEDUP_NV (entry-file #define): dedup with VK_NV_shader_subgroup_partitioned instead of REDUCE.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#if DEDUP_NV
#extension GL_NV_shader_subgroup_partitioned : require
#endif
#include "common.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };
layout(constant_id = 0) const uint EARLY_Z = 0;
layout(constant_id = 1) const uint REDUCE = 0;
layout(constant_id = 2) const uint JUST_SET = 0;
layout(constant_id = 3) const uint DEPTH_ONLY = 0; // payload 0, no color read (HQS depth pass)
// Points per thread: a workgroup draws kPointGroupSize * POINTS_PER_THREAD consecutive points, each
// thread loading all its positions before it projects any, for more loads in flight per thread.
layout(constant_id = 4) const uint POINTS_PER_THREAD = 1;

#include "point.inc.glsl"

// Subgroup operations on 64-bit words built from 32-bit ones. The H200 (NVIDIA 580) hung, at random,
// in kernels that used 64-bit subgroup arithmetic (docs/performance.md); 32-bit operations are what every
// device implements natively, and they need no shaderSubgroupExtendedTypes.
uint64_t joinWord(uint hi, uint lo) {
  return (uint64_t(hi) << 32) | uint64_t(lo);
}
uint64_t subgroupMinWord(uint64_t w) {
  uint hi = uint(w >> 32);
  uint leastHi = subgroupMin(hi);
  return joinWord(leastHi, subgroupMin(hi == leastHi ? uint(w) : 0xFFFFFFFFu));
}
uint64_t subgroupShuffleXorWord(uint64_t w, uint mask) {
  return joinWord(subgroupShuffleXor(uint(w >> 32), mask), subgroupShuffleXor(uint(w), mask));
}
#if DEDUP_NV
uint64_t partitionedMinWord(uint64_t w, uvec4 same) {
  uint hi = uint(w >> 32);
  uint leastHi = subgroupPartitionedMinNV(hi, same);
  return joinWord(leastHi, subgroupPartitionedMinNV(hi == leastHi ? uint(w) : 0xFFFFFFFFu, same));
}
#endif

void writeClosest(uint pixel, uint64_t word) {
  Uint64Array fb = Uint64Array(pc.framebuffer);
  if (EARLY_Z != 0 && word >= fb.v[pixel]) return;
  atomicMin(fb.v[pixel], word);
}

// Settles one point per lane (pixel == kNoPixel: no point) into the framebuffer. Called once per point
// of a thread, in a loop: every subgroup operation here runs in uniform control flow and nothing returns
// early, so all lanes leave together. (With an early return for some lanes, NVIDIA let them reach the
// next point's ballot and shuffles while their partners were still in this one: the GPU hung.)
void settle(uint pixel, uint64_t word) {
  bool valid = pixel != kNoPixel;
  bool writes = valid;   // whether this lane does an atomic
  uint64_t value = word; // and with which word
#if DEDUP_NV
  uvec4 same = subgroupPartitionNV(pixel);
  value = partitionedMinWord(word, same);
  writes = valid && gl_SubgroupInvocationID == subgroupBallotFindLSB(same);
#else
  if (JUST_SET == 0 && REDUCE == 1) {
    uvec4 busy = subgroupBallot(valid);
    if (subgroupBallotBitCount(busy) != 0) {
      uint leader = subgroupBallotFindLSB(busy);
      uint leaderPixel = subgroupShuffle(pixel, leader);
      if (subgroupAll(!valid || pixel == leaderPixel)) {
        // The whole subgroup hits one pixel: one atomic of the subgroup minimum.
        value = subgroupMinWord(word);
        writes = gl_SubgroupInvocationID == leader;
      } else {
        // Otherwise neighbouring pairs that share a pixel combine; the even lane writes.
        uint otherPixel = subgroupShuffleXor(pixel, 1);
        uint64_t otherWord = subgroupShuffleXorWord(word, 1);
        if (valid && otherPixel == pixel) {
          value = min(word, otherWord);
          writes = (gl_SubgroupInvocationID & 1u) == 0u;
        }
      }
    }
  } else if (JUST_SET == 0 && REDUCE == 2) {
    bool pending = valid;
    writes = false;
    // One round per distinct pixel: the lowest pending lane takes the minimum of the lanes sharing its
    // pixel and writes it after the loop. The loop body has no memory access and no branch (selects only),
    // and it runs at most once per lane.
    for (uint round = 0; round < gl_SubgroupSize && subgroupAny(pending); ++round) {
      uint leader = subgroupBallotFindLSB(subgroupBallot(pending));
      uint leaderPixel = subgroupShuffle(pixel, leader);
      bool mine = pending && pixel == leaderPixel;
      uint64_t least = subgroupMinWord(mine ? word : kEmptyPixel);
      bool lead = gl_SubgroupInvocationID == leader;
      writes = writes || lead;
      value = lead ? least : value;
      pending = pending && !mine;
    }
  }
#endif
  if (writes) {
    if (JUST_SET != 0)
      Uint64Array(pc.framebuffer).v[pixel] = value;
    else
      writeClosest(pixel, value);
  }
}

void main() {
  // No early return anywhere: the subgroup operations in settle() need every lane of the subgroup.
  uint first = firstPointOfThread(POINTS_PER_THREAD);
  vec3 positions[POINTS_PER_THREAD];
  for (uint k = 0; k < POINTS_PER_THREAD; ++k)
    positions[k] = loadPositionOrZero(first + k * kPointGroupSize);
  for (uint k = 0; k < POINTS_PER_THREAD; ++k) {
    uint i = first + k * kPointGroupSize;
    uint pixel = kNoPixel;
    uint64_t word = kEmptyPixel;
    if (i < pc.pointCount && depthWordOf(positions[k], pixel, word)) {
      // Early-z on the word without its payload: if even that cannot win, the color is never read.
      if (EARLY_Z != 0 && JUST_SET == 0 && word > Uint64Array(pc.framebuffer).v[pixel]) {
        pixel = kNoPixel;
      } else if (DEPTH_ONLY == 0) {
        word = withColor(word, i);
      }
    } else {
      pixel = kNoPixel;
    }
    if (pixel == kNoPixel) word = kEmptyPixel;
    settle(pixel, word);
  }
}

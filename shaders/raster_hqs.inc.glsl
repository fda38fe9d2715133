// High-quality splatting, accumulation pass (2019 paper, and the single-atomic form of the 2022 paper).
// The depth pass left the closest linear depth in the high word of the framebuffer; here every point
// whose linear depth is within 1 % of it adds its color to the pixel.
//   ONE_ROUND 0 (hqs):   aux = 2 uint64 per pixel: (r << 32 | g), (b << 32 | count); two atomicAdds
//   ONE_ROUND 1 (hqs1r): aux = 1 uint64 per pixel packing r, g, b, count in 16 bits each, one atomicAdd;
//                        then 2 uint64 per pixel of 32-bit fallback sums for points past the 255th.
// Contention: in dense views ~100 points per pixel blend, and neighbours in a subgroup mostly share a
// pixel, so lanes first add within the subgroup (PARTITIONED_NV: one partition per distinct pixel; else
// one sum when the whole subgroup shares a pixel) and one lane per group does the atomics. A subgroup
// has at most 128 lanes, so a group's sums (<= 128 * 255 = 32640 per color, <= 128 points) fit the
// 16-bit fields of the packed word.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#if PARTITIONED_NV
#extension GL_NV_shader_subgroup_partitioned : require
#endif
#include "common.inc.glsl"
#include "grid.inc.glsl"
#include "hqs_accumulate.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };
layout(constant_id = 0) const uint ONE_ROUND = 0;
#define DEPTH_INT40 0
#include "point.inc.glsl"

const uint kNoPixel = 0xFFFFFFFFu;

// hqs: two 64-bit sums per pixel. hqs1r: the single-atomic layout of hqs_accumulate.inc.glsl.
void accumulate(uint pixel, uint r, uint g, uint b, uint count) {
  Uint64Array acc = Uint64Array(pc.aux);
  if (ONE_ROUND != 0) {
    hqsAccumulate(acc, pc.width * pc.height, pixel, r, g, b, count);
    return;
  }
  atomicAdd(acc.v[2 * pixel], (uint64_t(r) << 32) | uint64_t(g));
  atomicAdd(acc.v[2 * pixel + 1], (uint64_t(b) << 32) | uint64_t(count));
}

void main() {
  uint i = linearInvocation(pc.groupsX, kPointGroupSize);
  uint pixel = kNoPixel;
  uint64_t word = 0;
  // No early return: the subgroup operations below need every lane active.
  if (i < pc.pointCount && pointWord(i, true, pixel, word)) {
    float closest = uintBitsToFloat(uint(Uint64Array(pc.framebuffer).v[pixel] >> 32));
    float depth = uintBitsToFloat(uint(word >> 32));
    if (depth > closest * float(PR_HQS_DEPTH_FACTOR)) pixel = kNoPixel; // hidden: not blended
  } else {
    // Not drawn. (Before projectPoint wrote its out parameters on every path, a point it dropped came
    // back with an undefined pixel here and was blended into it: atomics at arbitrary addresses.)
    pixel = kNoPixel;
  }
  // Sums within the subgroup in 32 bits (see raster_closest.inc.glsl on 64-bit subgroup arithmetic).
  uint r, g, b, count;
  bool writes;
#if PARTITIONED_NV
  bool blended = pixel != kNoPixel;
  uint color = uint(word);
  uvec4 same = subgroupPartitionNV(pixel);
  r = subgroupPartitionedAddNV(blended ? color & 0xFFu : 0u, same);
  g = subgroupPartitionedAddNV(blended ? (color >> 8) & 0xFFu : 0u, same);
  b = subgroupPartitionedAddNV(blended ? (color >> 16) & 0xFFu : 0u, same);
  count = subgroupPartitionedAddNV(blended ? 1u : 0u, same);
  writes = blended && gl_SubgroupInvocationID == subgroupBallotFindLSB(same);
#else
  hqsSubgroupSums(pixel, uint(word), r, g, b, count, writes);
#endif
  if (writes) accumulate(pixel, r, g, b, count);
}

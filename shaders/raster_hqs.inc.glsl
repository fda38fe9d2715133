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

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };
layout(constant_id = 0) const uint ONE_ROUND = 0;
#define DEPTH_INT40 0
#include "point.inc.glsl"

const uint kNoPixel = 0xFFFFFFFFu;

uint64_t joinPair(uint hi, uint lo) {
  return (uint64_t(hi) << 32) | uint64_t(lo);
}

void accumulate(uint pixel, uint64_t packed, uint64_t rg, uint64_t bn, uint count) {
  Uint64Array acc = Uint64Array(pc.aux);
  if (ONE_ROUND == 0) {
    atomicAdd(acc.v[2 * pixel], rg);
    atomicAdd(acc.v[2 * pixel + 1], bn);
    return;
  }
  // A pixel already full (as a plain read shows it) goes to the fallback sums at once: in dense views
  // thousands of points share a pixel, and the add-then-take-back pair below would put two atomics per
  // point on one hot address. The read may count adds that are about to be taken back; such a point then
  // uses the fallback although it might have fitted, which changes nothing in the resolved sums.
  if (uint(acc.v[pixel] >> 48) + count <= kHqs1rMaxCount) {
    uint64_t before = atomicAdd(acc.v[pixel], packed);
    if (uint(before >> 48) + count <= kHqs1rMaxCount) return;
    // The word would pass 255 points: take the add back (modular addition undoes exactly, whatever
    // carries happened meanwhile) and add to the 32-bit fallback sums instead. Adds that stay always saw
    // a total of at most 255 including themselves, so the packed fields never overflow in the final sums.
    atomicAdd(acc.v[pixel], -packed);
  }
  uint pixels = pc.width * pc.height;
  atomicAdd(acc.v[pixels + 2 * pixel], rg);
  atomicAdd(acc.v[pixels + 2 * pixel + 1], bn);
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
  bool blended = pixel != kNoPixel;
  // Sums within the subgroup in 32 bits (see raster_closest.inc.glsl on 64-bit subgroup arithmetic):
  // at most 128 lanes x 255 per channel.
  uint r = blended ? uint(word) & 0xFFu : 0u, g = blended ? (uint(word) >> 8) & 0xFFu : 0u;
  uint b = blended ? (uint(word) >> 16) & 0xFFu : 0u, one = blended ? 1u : 0u;
#if PARTITIONED_NV
  uvec4 same = subgroupPartitionNV(pixel);
  r = subgroupPartitionedAddNV(r, same);
  g = subgroupPartitionedAddNV(g, same);
  b = subgroupPartitionedAddNV(b, same);
  uint count = subgroupPartitionedAddNV(one, same);
  bool writes = blended && gl_SubgroupInvocationID == subgroupBallotFindLSB(same);
#else
  uint count = one;
  bool writes = blended;
  if (subgroupAllEqual(pixel)) {
    r = subgroupAdd(r);
    g = subgroupAdd(g);
    b = subgroupAdd(b);
    count = subgroupAdd(one);
    writes = blended && subgroupElect();
  }
#endif
  if (writes) {
    uint64_t packed = uint64_t(r) | (uint64_t(g) << 16) | (uint64_t(b) << 32) | (uint64_t(count) << 48);
    accumulate(pixel, packed, joinPair(r, g), joinPair(b, count), count);
  }
}

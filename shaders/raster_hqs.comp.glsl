#version 460
// High-quality splatting, accumulation pass (2019 paper; hqs1r: the single-atomic form of the 2022 paper).
// The depth pass left the closest linear depth in the high word of the framebuffer; here every point whose
// linear depth is within 1 % of it adds its color to the pixel (hqs_accumulate.inc.glsl).
//   ONE_ROUND 0 (hqs):   aux = 2 uint64 per pixel: (r << 32 | g), (b << 32 | count); two atomicAdds
//   ONE_ROUND 1 (hqs1r): aux = 1 uint64 per pixel packing r, g, b, count in 16 bits each, one atomicAdd;
//                        then 2 uint64 per pixel of 32-bit fallback sums for points past the 255th.
// Like raster_closest, a thread draws POINTS_PER_THREAD points a workgroup size apart (lanes of a subgroup
// hold consecutive points), loading all positions first; a point reads its color only once it is known to
// blend, so hidden points cost their 12 B of position alone.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_shuffle : require
#include "common.inc.glsl"
#include "hqs_accumulate.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { RasterPush pc; };
layout(constant_id = 0) const uint ONE_ROUND = 0;
layout(constant_id = 1) const uint POINTS_PER_THREAD = 1;
#define DEPTH_INT40 0
#include "point.inc.glsl"

void main() {
  // No early return anywhere: the subgroup operations of hqsBlend need every lane.
  uint first = firstPointOfThread(POINTS_PER_THREAD);
  vec3 positions[POINTS_PER_THREAD];
  for (uint k = 0; k < POINTS_PER_THREAD; ++k)
    positions[k] = loadPositionOrZero(first + k * kPointGroupSize);
  Uint64Array fb = Uint64Array(pc.framebuffer);
  for (uint k = 0; k < POINTS_PER_THREAD; ++k) {
    uint i = first + k * kPointGroupSize;
    uint pixel = kNoPixel, r = 0u, g = 0u, b = 0u;
    uint64_t word;
    if (i < pc.pointCount && depthWordOf(positions[k], pixel, word)) {
      float closest = uintBitsToFloat(uint(fb.v[pixel] >> 32));
      if (uintBitsToFloat(uint(word >> 32)) > closest * float(PR_HQS_DEPTH_FACTOR))
        pixel = kNoPixel; // hidden: not blended, its color never read
      else
        hqsChannels(UintArray(pc.colors).v[i], r, g, b);
    } else {
      pixel = kNoPixel;
    }
    hqsBlend(Uint64Array(pc.aux), pc.width * pc.height, ONE_ROUND != 0, pixel, r, g, b, pixel != kNoPixel ? 1u : 0u);
  }
}

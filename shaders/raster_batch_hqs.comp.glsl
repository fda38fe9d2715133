#version 460
// batch-hqs, accumulation pass (2022): after a depth pass (raster_batch.comp with PREFETCH and DEPTH_ONLY)
// left each pixel's closest depth in the framebuffer's high word, every point of a batch that is not culled
// and lies within 1 % of its pixel's closest depth adds its color with one packed atomicAdd (hqs1r's layout,
// resolved by resolve_hqs.comp). Same culling, precision and 128-bit loads as the depth pass, so both passes
// decode every point to the same position; colors are read for blended points only.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_EXT_control_flow_attributes : require
#include "batch.inc.glsl"
#include "hqs_accumulate.inc.glsl"

void main() {
  beginStats();
  FrameRef frame = FrameRef(pc.frame);
  uint width = frame.f.width, height = frame.f.height;
  Uint64Array fb = Uint64Array(frame.f.framebuffer);
  Uint64Array acc = Uint64Array(frame.f.accumulators);
  uint first = gl_WorkGroupID.x * kBatchPoints;
  uint count = min(kBatchPoints, pc.pointCount - first);
  BatchView v = viewBatch(gl_WorkGroupID.x, width, height, frame.f.forcedWords, frame.f.culling != 0u);
  uint blended = 0u;
  // No early exit from the loops: hqsBlend's subgroup operations need every lane (v is uniform).
  if (v.words != 0u) {
    for (uint j = 0u; j < kBatchPrefetchSteps; ++j) {
      uint local = 4u * (gl_LocalInvocationIndex + j * kPointGroupSize);
      uvec4 h = uvec4(0u), m = uvec4(0u), l = uvec4(0u);
      if (local < count) loadQuad((first + local) / 4u, v.words, h, m, l);
      // Four points in flight: project all, then their pixels' closest depths and the colors of those that
      // blend are read together, then they blend.
      uint pixel[4];
      float depth[4];
      [[unroll]] for (uint k = 0u; k < 4u; ++k) {
        uint p, depthBits;
        pixel[k] = kNoPixel;
        depth[k] = 0.0;
        if (local + k < count &&
            projectBatchPoint(v, v.words, true, h[k], m[k], l[k], width, height, p, depthBits)) {
          pixel[k] = p;
          depth[k] = uintBitsToFloat(depthBits);
        }
      }
      [[unroll]] for (uint k = 0u; k < 4u; ++k) {
        if (pixel[k] == kNoPixel) continue;
        float closest = uintBitsToFloat(uint(fb.v[pixel[k]] >> 32));
        if (depth[k] > closest * float(PR_HQS_DEPTH_FACTOR)) pixel[k] = kNoPixel; // hidden: not blended
      }
      // Colors of the points that blend; a thread's four points are consecutive and often share a pixel,
      // so the sums of a shared pixel go with its first point (fewer lanes for the subgroup to combine).
      uint r[4], g[4], b[4], n[4];
      [[unroll]] for (uint k = 0u; k < 4u; ++k) {
        r[k] = g[k] = b[k] = n[k] = 0u;
        if (pixel[k] == kNoPixel) continue;
        hqsChannels(UintArray(pc.colors).v[first + local + k], r[k], g[k], b[k]);
        n[k] = 1u;
        ++blended;
      }
      [[unroll]] for (uint k = 1u; k < 4u; ++k) {
        [[unroll]] for (uint e = 0u; e < k; ++e) {
          if (pixel[k] != kNoPixel && pixel[k] == pixel[e]) {
            r[e] += r[k];
            g[e] += g[k];
            b[e] += b[k];
            n[e] += n[k];
            pixel[k] = kNoPixel;
          }
        }
      }
      [[unroll]] for (uint k = 0u; k < 4u; ++k)
        hqsBlend(acc, width * height, true, pixel[k], r[k], g[k], b[k], n[k]);
    }
  }
  endStats(frame.f.stats, kStatPointsBlended, blended, false, v.words, count);
}

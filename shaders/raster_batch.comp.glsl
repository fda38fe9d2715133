#version 460
// batch and batch-prefetch (see batch.inc.glsl): each point of a batch that is not culled is decoded,
// projected, tested against the framebuffer (early-z) and, if closer, written with one 64-bit atomicMin of
// depth << 32 | visibility index (part << 26 | index in the part). Colors are fetched by the resolve, for
// visible points only.
//   PREFETCH   0: thread t draws points t + 128 j (j < 80), one 32-bit load per word
//              1: thread t loads the words of points 4 (t + 128 j) .. + 3 (j < 20) with one 128-bit load
//                 per word, four points in flight
//   DEPTH_ONLY 1: the word is depth << 32 alone (the depth pass of batch-hqs)
#extension GL_EXT_control_flow_attributes : require
#include "batch.inc.glsl"

layout(constant_id = 0) const uint PREFETCH = 0;
layout(constant_id = 1) const uint DEPTH_ONLY = 0;

// The low word: the visibility index of point `index` of the part, or 0 in a depth pass.
uint payloadOf(uint index) {
  return DEPTH_ONLY != 0u ? 0u : (pc.part << kVisibilityPartShift) | index;
}

// 1 if the point did the atomic, else 0.
uint drawPoint(vec3 p, uint index, Uint64Array fb, uint width, uint height) {
  uint pixel, depthBits;
  if (!projectPoint(pc.viewProj, p, width, height, pc.nearW, pixel, depthBits)) return 0u;
  uint64_t word = (uint64_t(depthBits) << 32) | uint64_t(payloadOf(index));
  if (word >= fb.v[pixel]) return 0u; // early-z: cannot win
  atomicMin(fb.v[pixel], word);
  return 1u;
}

void main() {
  beginStats();
  FrameRef frame = FrameRef(pc.frame);
  uint width = frame.f.width, height = frame.f.height;
  Uint64Array fb = Uint64Array(frame.f.framebuffer);
  uint first = gl_WorkGroupID.x * kBatchPoints;
  uint count = min(kBatchPoints, pc.pointCount - first);
  BatchView v = viewBatch(gl_WorkGroupID.x, width, height, frame.f.forcedWords, frame.f.culling != 0u);
  uint rendered = 0u;
  if (v.words != 0u && PREFETCH == 0u) {
    UintArray high = UintArray(pc.high), medium = UintArray(pc.medium), low = UintArray(pc.low);
    for (uint j = 0u; j < kBatchPointsPerThread; ++j) {
      uint local = gl_LocalInvocationIndex + j * kPointGroupSize;
      if (local >= count) break;
      uint i = first + local;
      uint h = high.v[i], m = 0u, l = 0u;
      if (v.words >= 2u) m = medium.v[i];
      if (v.words >= 3u) l = low.v[i];
      rendered += drawPoint(decodePoint(v, h, m, l), i, fb, width, height);
    }
  } else if (v.words != 0u) {
    Uvec4Array high = Uvec4Array(pc.high), medium = Uvec4Array(pc.medium), low = Uvec4Array(pc.low);
    // (Loading the next step's words before this step's points were drawn made batch-prefetch 18 %
    // slower on the H200: bench/NOTES.md.)
    for (uint j = 0u; j < kBatchPrefetchSteps; ++j) {
      uint local = 4u * (gl_LocalInvocationIndex + j * kPointGroupSize);
      if (local >= count) break;
      uint g = (first + local) / 4u; // first is a multiple of 10240; word buffers are padded to 4 points
      uvec4 h = high.v[g], m = uvec4(0u), l = uvec4(0u);
      if (v.words >= 2u) m = medium.v[g];
      if (v.words >= 3u) l = low.v[g];
      // Project the four points, read their pixels, then do the atomics: the reads are independent and go out
      // together.
      uint pixel[4];
      uint64_t word[4], seen[4];
      [[unroll]] for (uint k = 0u; k < 4u; ++k) {
        uint p, depthBits;
        pixel[k] = kNoPixel;
        word[k] = kEmptyPixel;
        if (local + k < count && projectPoint(pc.viewProj, decodePoint(v, h[k], m[k], l[k]), width, height,
                                              pc.nearW, p, depthBits)) {
          pixel[k] = p;
          word[k] = (uint64_t(depthBits) << 32) | uint64_t(payloadOf(first + local + k));
        }
      }
      // Consecutive points often share a pixel: the closest of the four on a pixel stands for the others, so
      // reading all four pixels before writing adds no atomics for points that share one.
      [[unroll]] for (uint k = 1u; k < 4u; ++k) {
        [[unroll]] for (uint e = 0u; e < k; ++e) {
          if (pixel[k] != kNoPixel && pixel[k] == pixel[e]) {
            word[e] = min(word[e], word[k]);
            pixel[k] = kNoPixel;
          }
        }
      }
      [[unroll]] for (uint k = 0u; k < 4u; ++k) {
        seen[k] = 0ul;
        if (pixel[k] != kNoPixel) seen[k] = fb.v[pixel[k]];
      }
      [[unroll]] for (uint k = 0u; k < 4u; ++k) {
        if (word[k] < seen[k]) { // early-z; seen is 0 for dropped points
          atomicMin(fb.v[pixel[k]], word[k]);
          ++rendered;
        }
      }
    }
  }
  endStats(frame.f.stats, kStatPointsRendered, rendered, true, v.words, count);
}

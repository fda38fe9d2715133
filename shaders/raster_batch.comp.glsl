#version 460
// batch and batch-prefetch (see batch.inc.glsl): each point of a batch that is not culled is decoded,
// projected, tested against the framebuffer (early-z) and, if not farther, written with one 64-bit
// atomicMin of depth << 32 | visibility index (part << 26 | index in the part). Colors are fetched by the
// resolve, for visible points only.
//   PREFETCH   0: thread t draws points t + 128 j (j < 80), one 32-bit load per word
//              1: thread t loads the words of points 4 (t + 128 j) .. + 3 (j < 20) with one 128-bit load
//                 per word
//   DEPTH_ONLY 1: the word is depth << 32 alone (the depth pass of batch-hqs)
//   Either way a thread has 4 points in flight: their words are loaded together, then all 4 projected,
//   then their pixels read, then the atomics done, so that neither the loads of the words nor those of the
//   pixels wait for one another. A point on the same pixel as the thread's previous point of the four takes
//   the closer of the two words and the previous one is dropped before its read (fewer atomics where
//   consecutive points share pixels, as in Morton order). The variants timed before choosing this shape
//   are in bench/NOTES.md (session 4).
#extension GL_EXT_control_flow_attributes : require
#include "batch.inc.glsl"

layout(constant_id = 0) const uint PREFETCH = 0;
layout(constant_id = 1) const uint DEPTH_ONLY = 0;
const uint GROUP = 4u; // points in flight per thread

// The framebuffer word's high half (the depth) of pixel p is word 2p + 1 of this view (little-endian).
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer DepthHalves { uint v[]; };

// Index in the batch of point u (< GROUP) of a thread's step `step`.
uint pointOfStep(uint step, uint u) {
  if (PREFETCH == 0u) return gl_LocalInvocationIndex + (step * GROUP + u) * kPointGroupSize;
  return 4u * (gl_LocalInvocationIndex + step * kPointGroupSize) + u;
}

// Draws the batch's points: `words` of them per point, `checked` = test each point against the batch's
// point count, the near plane and the image (a batch that is not entirely inside, or a part's last batch).
// Called with constant arguments, so each combination compiles to its own loop. Returns the atomics done.
uint drawBatch(BatchView v, uint words, bool checked, uint first, uint count, uint width, uint height) {
  uint64_t framebuffer = FrameRef(pc.frame).f.framebuffer;
  Uint64Array fb = Uint64Array(framebuffer);
  DepthHalves depths = DepthHalves(framebuffer);
  UintArray high = UintArray(pc.high), medium = UintArray(pc.medium), low = UintArray(pc.low);
  uint rendered = 0u;
  for (uint step = 0u; step < kBatchPointsPerThread / GROUP; ++step) {
    uint h[GROUP], m[GROUP], l[GROUP];
    if (PREFETCH == 0u) {
      [[unroll]] for (uint u = 0u; u < GROUP; ++u) {
        uint local = pointOfStep(step, u);
        h[u] = m[u] = l[u] = 0u;
        if (checked && local >= count) continue;
        h[u] = high.v[first + local];
        if (words >= 2u) m[u] = medium.v[first + local];
        if (words >= 3u) l[u] = low.v[first + local];
      }
    } else {
      uint local = pointOfStep(step, 0u);
      // Word buffers are padded to a multiple of 4 points, and `first` is a multiple of 10240.
      uvec4 hq = uvec4(0u), mq = uvec4(0u), lq = uvec4(0u);
      if (!checked || local < count) loadQuad((first + local) / 4u, words, hq, mq, lq);
      [[unroll]] for (uint u = 0u; u < GROUP; ++u) {
        h[u] = hq[u];
        m[u] = mq[u];
        l[u] = lq[u];
      }
    }
    uint pixel[GROUP], depth[GROUP], payload[GROUP];
    [[unroll]] for (uint u = 0u; u < GROUP; ++u) {
      uint local = pointOfStep(step, u);
      payload[u] = DEPTH_ONLY != 0u ? 0u : (pc.part << kVisibilityPartShift) | (first + local);
      if ((checked && local >= count) ||
          !projectBatchPoint(v, words, checked, h[u], m[u], l[u], width, height, pixel[u], depth[u])) {
        pixel[u] = kNoPixel;
        depth[u] = 0xFFFFFFFFu; // above any seen value: no atomic
      }
      if (u > 0u && pixel[u] == pixel[u - 1u] && pixel[u] != kNoPixel) {
        // Keep the smaller word: the closer point, or on equal depth the lower index (u - 1).
        if (depth[u - 1u] <= depth[u]) {
          depth[u] = depth[u - 1u];
          payload[u] = payload[u - 1u];
        }
        pixel[u - 1u] = kNoPixel;
        depth[u - 1u] = 0xFFFFFFFFu;
      }
    }
    uint seen[GROUP];
    [[unroll]] for (uint u = 0u; u < GROUP; ++u)
      seen[u] = pixel[u] != kNoPixel ? depths.v[2u * pixel[u] + 1u] : 0u;
    [[unroll]] for (uint u = 0u; u < GROUP; ++u) {
      // Early-z on the depth half: a point not farther than the pixel's closest may still win (equal
      // depths are decided by the index in the atomic). Dropped points have seen = 0 < depth.
      if (depth[u] <= seen[u]) {
        atomicMin(fb.v[pixel[u]], (uint64_t(depth[u]) << 32) | uint64_t(payload[u]));
        ++rendered;
      }
    }
  }
  return rendered;
}

void main() {
  beginStats();
  FrameRef frame = FrameRef(pc.frame);
  uint width = frame.f.width, height = frame.f.height;
  uint first = gl_WorkGroupID.x * kBatchPoints;
  uint count = min(kBatchPoints, pc.pointCount - first);
  BatchView v = viewBatch(gl_WorkGroupID.x, width, height, frame.f.forcedWords, frame.f.culling != 0u);
  uint rendered = 0u;
  if (v.inside && count == kBatchPoints) {
    if (v.words == 1u) rendered = drawBatch(v, 1u, false, first, count, width, height);
    else if (v.words == 2u) rendered = drawBatch(v, 2u, false, first, count, width, height);
    else if (v.words == 3u) rendered = drawBatch(v, 3u, false, first, count, width, height);
  } else {
    if (v.words == 1u) rendered = drawBatch(v, 1u, true, first, count, width, height);
    else if (v.words == 2u) rendered = drawBatch(v, 2u, true, first, count, width, height);
    else if (v.words == 3u) rendered = drawBatch(v, 3u, true, first, count, width, height);
  }
  endStats(frame.f.stats, kStatPointsRendered, rendered, true, v.words, count);
}

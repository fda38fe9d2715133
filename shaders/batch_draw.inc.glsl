// The closest-point drawing loop of the batch passes, for any box of quantized points (batch.inc.glsl):
// a batch of a part (raster_batch.comp) or a page of an octree node (raster_lod.comp). Each point of a box
// that is not culled is decoded, projected, tested against the framebuffer (early-z) and, if not farther,
// written with one 64-bit atomicMin of depth << 32 | visibility index (payloadBase + the point's index in
// the box). The includer declares the specialization constants
//   PREFETCH   0: thread t draws points t + 128 j, one 32-bit load per word
//              1: thread t loads the words of points 4 (t + 128 j) .. + 3 with one 128-bit load per word
//   DEPTH_ONLY 1: the word is depth << 32 alone (the depth pass of the HQS methods)
// Either way a thread has 4 points in flight: their words are loaded together, then all 4 projected, then
// their pixels read, then the atomics done, so that neither the loads of the words nor those of the pixels
// wait for one another. A point on the same pixel as the thread's previous point of the four takes the
// closer of the two words and the previous one is dropped before its read (fewer atomics where consecutive
// points share pixels, as in Morton order). The variants timed before choosing this shape are in
// docs/performance.md.
#extension GL_EXT_control_flow_attributes : require

const uint GROUP = 4u; // points in flight per thread

// The framebuffer word's high half (the depth) of pixel p is v[p].y of this view (little-endian): the same
// address as the atomic's on word p plus an immediate 4, where indexing a uint view at 2p + 1 (32-bit
// arithmetic that may wrap) made the compiler compute a second address per point.
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer DepthHalves { uvec2 v[]; };

// Index in the box of point u (< GROUP) of a thread's step `step`.
uint pointOfStep(uint step, uint u) {
  if (PREFETCH == 0u) return gl_LocalInvocationIndex + (step * GROUP + u) * kPointGroupSize;
  return 4u * (gl_LocalInvocationIndex + step * kPointGroupSize) + u;
}

// The words of a thread's step `step` of the box: its GROUP points' first `words` words (zeros for the others
// and past the box's `count` points when `checked`).
void loadStep(uint step, uint words, bool checked, BatchWords at, uint count, out uint h[GROUP], out uint m[GROUP],
              out uint l[GROUP]) {
  if (PREFETCH == 0u) {
    UintArray high = UintArray(at.high), medium = UintArray(at.medium), low = UintArray(at.low);
    [[unroll]] for (uint u = 0u; u < GROUP; ++u) {
      uint local = pointOfStep(step, u);
      h[u] = m[u] = l[u] = 0u;
      if (checked && local >= count) continue;
      h[u] = high.v[local];
      if (words >= 2u) m[u] = medium.v[local];
      if (words >= 3u) l[u] = low.v[local];
    }
  } else {
    uint local = pointOfStep(step, 0u);
    // Word buffers are padded to a multiple of 4 points, and a box starts at a multiple of 4.
    uvec4 hq = uvec4(0u), mq = uvec4(0u), lq = uvec4(0u);
    if (!checked || local < count) loadQuad(at, local / 4u, words, hq, mq, lq);
    [[unroll]] for (uint u = 0u; u < GROUP; ++u) {
      h[u] = hq[u];
      m[u] = mq[u];
      l[u] = lq[u];
    }
  }
}

// Projects the loaded points of a step with `words` words each into one camera's image and does their atomics;
// `checked` = test each point against the count, the near plane and the image. Returns the atomics done.
uint drawStep(BatchView v, uint words, bool checked, uint h[GROUP], uint m[GROUP], uint l[GROUP], uint step,
              uint payloadBase, uint count, BatchCamera cam, uint64_t framebuffer) {
  Uint64Array fb = Uint64Array(framebuffer);
  DepthHalves depths = DepthHalves(framebuffer);
  uint pixel[GROUP], depth[GROUP], payload[GROUP];
  // Whether every point projects to a pixel: no test can drop one (projectInside), so the merge below need
  // not ask whether point u was dropped (a compare a point, on the path of every point of the overview).
  const bool allProjected = !checked && words != 3u;
  [[unroll]] for (uint u = 0u; u < GROUP; ++u) {
    uint local = pointOfStep(step, u);
    payload[u] = DEPTH_ONLY != 0u ? 0u : payloadBase + local;
    if ((checked && local >= count) ||
        !projectBatchPoint(v, words, checked, h[u], m[u], l[u], cam, pixel[u], depth[u])) {
      pixel[u] = kNoPixel;
      depth[u] = 0xFFFFFFFFu; // above any seen value: no atomic
    }
    if (u > 0u && pixel[u] == pixel[u - 1u] && (allProjected || pixel[u] != kNoPixel)) {
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
    seen[u] = pixel[u] != kNoPixel ? depths.v[pixel[u]].y : 0u;
  uint rendered = 0u;
  [[unroll]] for (uint u = 0u; u < GROUP; ++u) {
    // Early-z on the depth half: a point not farther than the pixel's closest may still win (equal
    // depths are decided by the index in the atomic). Dropped points have seen = 0 < depth.
    if (depth[u] <= seen[u]) {
      atomicMin(fb.v[pixel[u]], (uint64_t(depth[u]) << 32) | uint64_t(payload[u]));
      ++rendered;
    }
  }
  return rendered;
}

// Draws the box's `count` points with `words` words each; `checked` = test each point against the count,
// the near plane and the image (a box that is not entirely inside, or not full). `steps` steps of GROUP
// points per thread cover the largest box of the pass. Called with constant words, checked and steps, so
// each combination compiles to its own loop. Returns the atomics done.
uint drawBox(BatchView v, uint words, bool checked, BatchWords at, uint payloadBase, uint count, uint steps,
             BatchCamera cam, uint64_t framebuffer) {
  uint rendered = 0u;
  for (uint step = 0u; step < steps; ++step) {
    uint h[GROUP], m[GROUP], l[GROUP];
    loadStep(step, words, checked, at, count, h, m, l);
    rendered += drawStep(v, words, checked, h, m, l, step, payloadBase, count, cam, framebuffer);
  }
  return rendered;
}

// drawBox with the words and the checks of the box decision: the one call of a drawing pass.
uint drawBoxAs(BatchView v, BatchWords at, uint payloadBase, uint count, uint fullCount, uint steps,
               BatchCamera cam, uint64_t framebuffer) {
  uint rendered = 0u;
  if (v.inside && count == fullCount) {
    if (v.words == 1u) rendered = drawBox(v, 1u, false, at, payloadBase, count, steps, cam, framebuffer);
    else if (v.words == 2u) rendered = drawBox(v, 2u, false, at, payloadBase, count, steps, cam, framebuffer);
    else if (v.words == 3u) rendered = drawBox(v, 3u, false, at, payloadBase, count, steps, cam, framebuffer);
  } else {
    if (v.words == 1u) rendered = drawBox(v, 1u, true, at, payloadBase, count, steps, cam, framebuffer);
    else if (v.words == 2u) rendered = drawBox(v, 2u, true, at, payloadBase, count, steps, cam, framebuffer);
    else if (v.words == 3u) rendered = drawBox(v, 3u, true, at, payloadBase, count, steps, cam, framebuffer);
  }
  return rendered;
}

// Stereo (2022, section 3.7): each step's words are loaded once, for the eye that needs more of them, and its
// points drawn into each eye with that eye's own box decision (words0, words1; 0 = culled for that eye), so
// each half of the framebuffer gets exactly what a mono pass with that eye's camera writes.
uint drawBoxStereo(BatchView v0, BatchView v1, uint words0, uint words1, bool checked, BatchWords at,
                   uint payloadBase, uint count, uint steps, BatchCamera cam0, BatchCamera cam1,
                   uint64_t framebuffer) {
  uint loaded = max(words0, words1);
  uint rendered = 0u;
  for (uint step = 0u; step < steps; ++step) {
    uint h[GROUP], m[GROUP], l[GROUP];
    loadStep(step, loaded, checked, at, count, h, m, l);
    if (words0 != 0u) rendered += drawStep(v0, words0, checked, h, m, l, step, payloadBase, count, cam0, framebuffer);
    if (words1 != 0u) rendered += drawStep(v1, words1, checked, h, m, l, step, payloadBase, count, cam1, framebuffer);
  }
  return rendered;
}

// drawBoxStereo with the two eyes' decisions: constant words and checks where both eyes agree on the words
// (nearly always: the eyes are a few centimetres apart), one general loop otherwise.
uint drawBoxAsStereo(BatchView v0, BatchView v1, BatchWords at, uint payloadBase, uint count, uint fullCount,
                     uint steps, BatchCamera cam0, BatchCamera cam1, uint64_t framebuffer) {
  if (v0.words != v1.words)
    return drawBoxStereo(v0, v1, v0.words, v1.words, true, at, payloadBase, count, steps, cam0, cam1,
                         framebuffer);
  uint w = v0.words;
  if (v0.inside && v1.inside && count == fullCount) {
    if (w == 1u) return drawBoxStereo(v0, v1, 1u, 1u, false, at, payloadBase, count, steps, cam0, cam1, framebuffer);
    if (w == 2u) return drawBoxStereo(v0, v1, 2u, 2u, false, at, payloadBase, count, steps, cam0, cam1, framebuffer);
    if (w == 3u) return drawBoxStereo(v0, v1, 3u, 3u, false, at, payloadBase, count, steps, cam0, cam1, framebuffer);
  } else {
    if (w == 1u) return drawBoxStereo(v0, v1, 1u, 1u, true, at, payloadBase, count, steps, cam0, cam1, framebuffer);
    if (w == 2u) return drawBoxStereo(v0, v1, 2u, 2u, true, at, payloadBase, count, steps, cam0, cam1, framebuffer);
    if (w == 3u) return drawBoxStereo(v0, v1, 3u, 3u, true, at, payloadBase, count, steps, cam0, cam1, framebuffer);
  }
  return 0u;
}

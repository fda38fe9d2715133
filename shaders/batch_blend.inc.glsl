// The accumulation loop of the HQS batch passes, for any box of quantized points (batch.inc.glsl): a batch
// of a part (raster_batch_hqs.comp) or a page of an octree node (raster_lod_hqs.comp). After a depth pass
// left each pixel's closest depth in the framebuffer's high word, every point of a box that is not culled
// and lies within 1 % of its pixel's closest depth adds its color with one packed atomicAdd (hqs1r's
// layout, resolved by resolve_hqs.comp). Same culling, precision and 128-bit loads as the depth pass, so
// both passes decode every point to the same position; colors are read for blended points only. Needs
// hqs_accumulate.inc.glsl and its subgroup extensions.

// Blends the loaded points of step j (their words in h, m, l, `words` of them) into one camera's image; if
// `flags` is not 0, only those on pixels it marks kHqsDenseFlagged (uint per pixel, BatchFrame::denseDepths).
// Returns the points blended. Call in uniform control flow (hqsBlend's subgroup operations need every lane).
uint blendStep(BatchView v, uint words, uvec4 h, uvec4 m, uvec4 l, uint local, BatchWords at, uint count,
               BatchCamera cam, uint64_t framebuffer, uint64_t accumulators, uint64_t flags) {
  Uint64Array fb = Uint64Array(framebuffer);
  Uint64Array acc = Uint64Array(accumulators);
  uint pixels = cam.pitch * cam.height; // the whole framebuffer: both eyes of a stereo frame
  uint blended = 0u;
  // Four points in flight: project all, then their pixels' closest depths and the colors of those that
  // blend are read together, then they blend.
  uint pixel[4];
  float depth[4];
  [[unroll]] for (uint k = 0u; k < 4u; ++k) {
    uint p, depthBits;
    pixel[k] = kNoPixel;
    depth[k] = 0.0;
    if (local + k < count && projectBatchPoint(v, words, true, h[k], m[k], l[k], cam, p, depthBits)) {
      pixel[k] = p;
      depth[k] = uintBitsToFloat(depthBits);
    }
  }
  [[unroll]] for (uint k = 0u; k < 4u; ++k) {
    if (pixel[k] == kNoPixel) continue;
    float closest = uintBitsToFloat(uint(fb.v[pixel[k]] >> 32));
    if (depth[k] > closest * float(PR_HQS_DEPTH_FACTOR)) pixel[k] = kNoPixel; // hidden: not blended
    else if (flags != 0ul && UintArray(flags).v[pixel[k]] != kHqsDenseFlagged) pixel[k] = kNoPixel;
  }
  // Colors of the points that blend; a thread's four points are consecutive and often share a pixel, so
  // they are added per pixel first (fewer lanes for the subgroup to combine, fewer subgroup steps).
  uint r[4], g[4], b[4], n[4];
  [[unroll]] for (uint k = 0u; k < 4u; ++k) {
    r[k] = g[k] = b[k] = n[k] = 0u;
    if (pixel[k] == kNoPixel) continue;
    hqsChannels(UintArray(at.colors).v[local + k], r[k], g[k], b[k]);
    n[k] = 1u;
    ++blended;
  }
  hqsMergeFour(pixel, r, g, b, n);
  [[unroll]] for (uint k = 0u; k < 4u; ++k)
    hqsBlend(acc, pixels, true, pixel[k], r[k], g[k], b[k], n[k]);
  return blended;
}

// Blends the box's `count` points; `steps` steps of 4 points per thread cover the largest box of the pass.
// Returns the points this thread blended. Call in uniform control flow (v is uniform).
uint blendBox(BatchView v, BatchWords at, uint count, uint steps, BatchCamera cam, uint64_t framebuffer,
              uint64_t accumulators, uint64_t flags) {
  uint blended = 0u;
  // No early exit from the loops: hqsBlend's subgroup operations need every lane.
  if (v.words == 0u) return 0u;
  for (uint j = 0u; j < steps; ++j) {
    uint local = 4u * (gl_LocalInvocationIndex + j * kPointGroupSize);
    uvec4 h = uvec4(0u), m = uvec4(0u), l = uvec4(0u);
    if (local < count) loadQuad(at, local / 4u, v.words, h, m, l);
    blended += blendStep(v, v.words, h, m, l, local, at, count, cam, framebuffer, accumulators, flags);
  }
  return blended;
}

// Stereo: each step's words loaded once (for the eye that needs more), blended into each eye not culled for
// it with that eye's decision, as drawBoxStereo draws them. The eyes' decisions are uniform.
uint blendBoxStereo(BatchView v0, BatchView v1, BatchWords at, uint count, uint steps, BatchCamera cam0,
                    BatchCamera cam1, uint64_t framebuffer, uint64_t accumulators) {
  uint loaded = max(v0.words, v1.words);
  uint blended = 0u;
  if (loaded == 0u) return 0u;
  for (uint j = 0u; j < steps; ++j) {
    uint local = 4u * (gl_LocalInvocationIndex + j * kPointGroupSize);
    uvec4 h = uvec4(0u), m = uvec4(0u), l = uvec4(0u);
    if (local < count) loadQuad(at, local / 4u, loaded, h, m, l);
    if (v0.words != 0u)
      blended += blendStep(v0, v0.words, h, m, l, local, at, count, cam0, framebuffer, accumulators, 0ul);
    if (v1.words != 0u)
      blended += blendStep(v1, v1.words, h, m, l, local, at, count, cam1, framebuffer, accumulators, 0ul);
  }
  return blended;
}

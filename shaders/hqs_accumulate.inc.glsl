// The single-atomic HQS accumulation of the 2022 paper (hqs1r's layout, resolved by resolve_hqs.comp with
// ONE_ROUND = 1): one uint64_t per pixel packs r, g, b, count in 16 bits each; a pixel stays exact up to 255
// points (255 x 255 < 2^16), later points go to two 32-bit-per-channel fallback words per pixel after the
// packed words. Lanes of a subgroup that all blend into one pixel add up first (dense views), in 32 bits.
// Needs the subgroup basic/vote/arithmetic extensions and common.inc.glsl.

// acc: packed words [0, pixels), then fallback (r << 32 | g, b << 32 | count) pairs.
void hqsAccumulate(Uint64Array acc, uint pixels, uint pixel, uint r, uint g, uint b, uint count) {
  uint64_t packed = uint64_t(r) | (uint64_t(g) << 16) | (uint64_t(b) << 32) | (uint64_t(count) << 48);
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
  atomicAdd(acc.v[pixels + 2 * pixel], (uint64_t(r) << 32) | uint64_t(g));
  atomicAdd(acc.v[pixels + 2 * pixel + 1], (uint64_t(b) << 32) | uint64_t(count));
}

// The sums one lane adds for one point per lane (pixel == 0xFFFFFFFF: none) of RGBA8 `color`, and whether
// this lane adds them (`writes`). Call in uniform control flow: when the whole subgroup shares one pixel,
// one lane adds the subgroup's sums (<= 128 lanes x 255 per channel, so they fit the 16-bit fields).
void hqsSubgroupSums(uint pixel, uint color, out uint r, out uint g, out uint b, out uint count,
                     out bool writes) {
  bool blended = pixel != 0xFFFFFFFFu;
  r = blended ? color & 0xFFu : 0u;
  g = blended ? (color >> 8) & 0xFFu : 0u;
  b = blended ? (color >> 16) & 0xFFu : 0u;
  count = blended ? 1u : 0u;
  writes = blended;
  if (subgroupAllEqual(pixel)) {
    r = subgroupAdd(r);
    g = subgroupAdd(g);
    b = subgroupAdd(b);
    count = subgroupAdd(count);
    writes = blended && subgroupElect();
  }
}

// Blends one point per lane into the single-atomic layout. Call in uniform control flow.
void hqsBlend(Uint64Array acc, uint pixels, uint pixel, uint color) {
  uint r, g, b, count;
  bool writes;
  hqsSubgroupSums(pixel, color, r, g, b, count, writes);
  if (writes) hqsAccumulate(acc, pixels, pixel, r, g, b, count);
}

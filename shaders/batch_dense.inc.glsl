// batch-hqs's dense batches (batch_part.inc.glsl: denseRect, denseBatch): depth and blending in one pass
// over the points.
//
// In a dense view every pixel takes hundreds of a batch's points, nearly all within 1 % of its closest depth:
// a batch's 10240 points fall on a few dozen pixels. So a dense batch adds every point's color to its pixel at
// once, and records per pixel the closest depth (the framebuffer's depth half, as the depth pass) and the
// farthest depth it blended (BatchFrame::denseDepths). After the pass, hqs_dense_check.comp finds the pixels
// where some dense point lies beyond 1 % of the closest depth; it drops their sums and flags them, and the
// accumulation pass blends again the dense batches' points on flagged pixels only, with the usual test. The
// other pixels' dense sums are exactly those of the two-pass method: every point added passes its test.
//
// A thread walks kDenseRun consecutive points and adds those on one pixel in registers (a run), so a point
// costs its projection and a few adds. Consecutive threads of a subgroup hold consecutive pieces, and a
// subgroup's pieces follow each other through the batch; a run that crosses pieces is joined across lanes by
// a segmented scan and across steps by a carry, so one set of atomics is done per run (in the 1 G Morton
// overview, 46 M runs: one per 21 points). Needs batch_part.inc.glsl and the subgroup basic and shuffle (with
// relative) extensions.

// Points a thread walks at a time; 80 / kDenseRun steps cover a batch. On the H200, 8 took 3.63 ms for the
// 1 G overview where 4 took 4.7 (twice the scans) and 16 took 4.5-7.2 (docs/performance.md).
const uint kDenseRun = 8u;
const uint kDenseQuads = kDenseRun / 4u;

// Consecutive points of a piece on one pixel: their channel sums, count and depth range (depth bits).
struct DenseRun {
  uint pixel; // kNoPixel: no run
  uint r, g, b, n;
  uint near, far;
};

DenseRun denseRunAt(uint pixel) {
  return DenseRun(pixel, 0u, 0u, 0u, 0u, 0xFFFFFFFFu, 0u);
}

// a then b, on the same pixel.
DenseRun denseJoin(DenseRun a, DenseRun b) {
  return DenseRun(b.pixel, a.r + b.r, a.g + b.g, a.b + b.b, a.n + b.n, min(a.near, b.near), max(a.far, b.far));
}

DenseRun denseShuffle(DenseRun x, uint lane) {
  return DenseRun(subgroupShuffle(x.pixel, lane), subgroupShuffle(x.r, lane), subgroupShuffle(x.g, lane),
                  subgroupShuffle(x.b, lane), subgroupShuffle(x.n, lane), subgroupShuffle(x.near, lane),
                  subgroupShuffle(x.far, lane));
}

DenseRun denseShuffleUp(DenseRun x, uint delta) {
  return DenseRun(subgroupShuffleUp(x.pixel, delta), subgroupShuffleUp(x.r, delta), subgroupShuffleUp(x.g, delta),
                  subgroupShuffleUp(x.b, delta), subgroupShuffleUp(x.n, delta), subgroupShuffleUp(x.near, delta),
                  subgroupShuffleUp(x.far, delta));
}

// Where a dense pass writes.
struct DenseTargets {
  Uint64Array framebuffer; // depth bits << 32 (the depth pass's words)
  Uint64Array acc;         // hqs1r's accumulators
  UintArray far;           // BatchFrame::denseDepths
  uint pixels;             // of the framebuffer
};

// Adds a finished run to its pixel: the sums to hqs1r's 32-bit fallback words (the resolve adds them to the
// packed word), the closest and the farthest depth where they change them. The two reads are issued together
// and the sums need no result back: a write waits for the L2 once. Returns the depth atomics done (0 or 1).
uint denseWrite(DenseRun run, DenseTargets t) {
  uint closest = uint(t.framebuffer.v[run.pixel] >> 32), farthest = t.far.v[run.pixel];
  atomicAdd(t.acc.v[t.pixels + 2u * run.pixel], (uint64_t(run.r) << 32) | uint64_t(run.g));
  atomicAdd(t.acc.v[t.pixels + 2u * run.pixel + 1u], (uint64_t(run.b) << 32) | uint64_t(run.n));
  if (run.far > farthest) atomicMax(t.far.v[run.pixel], run.far);
  if (run.near >= closest) return 0u;
  atomicMin(t.framebuffer.v[run.pixel], uint64_t(run.near) << 32);
  return 1u;
}

// Loads the words and colors of a thread's kDenseRun points from quad `quad` on.
void denseLoad(BatchWords at, uint quad, out uvec4 words[kDenseQuads], out uvec4 colors[kDenseQuads]) {
  [[unroll]] for (uint q = 0u; q < kDenseQuads; ++q) {
    words[q] = Uvec4Array(at.high).v[quad + q];
    colors[q] = Uvec4Array(at.colors).v[quad + q];
  }
}

// A run summed within a thread keeps red and blue in one word (r | b << 16: at most kDenseRun x 255 each);
// this spreads them out.
DenseRun denseUnpack(DenseRun run) {
  return DenseRun(run.pixel, run.r & 0xFFFFu, run.g, run.r >> 16, run.n, run.near, run.far);
}

// Draws a dense batch (denseBatch): every point blended into its pixel. Returns the depth atomics done by
// this thread. Call in uniform control flow, by every thread of the workgroup.
uint drawDense(BatchView v, BatchWords at, BatchCamera cam, DenseTargets t) {
  uint lane = gl_SubgroupInvocationID, size = gl_SubgroupSize;
  // Subgroup s draws points [80 size s, 80 size (s + 1)) of the batch, kDenseRun size of them a step.
  uint piece = gl_SubgroupID * kBatchPointsPerThread * size + lane * kDenseRun;
  uint writes = 0u;
  DenseRun carry = denseRunAt(kNoPixel); // the subgroup's open run from the step before (uniform)
  for (uint step = 0u; step < kBatchPointsPerThread / kDenseRun; ++step) {
    // (Loading the next step's points while drawing these was slower on the H200: more registers.)
    uvec4 words[kDenseQuads], colors[kDenseQuads];
    denseLoad(at, (piece + step * size * kDenseRun) / 4u, words, colors);
    // The piece's runs: the first is kept in `head` (an earlier lane may continue it), the last in `run`
    // (a later lane may), those between are complete and written at once.
    DenseRun head = denseRunAt(kNoPixel), run = denseRunAt(kNoPixel);
    [[unroll]] for (uint i = 0u; i < kDenseRun; ++i) {
      uint pixel, depth;
      projectBatchPoint(v, 1u, false, words[i / 4u][i % 4u], 0u, 0u, cam, pixel, depth);
      if (pixel != run.pixel) {
        if (run.pixel != kNoPixel) {
          if (head.pixel == kNoPixel) head = denseUnpack(run);
          else writes += denseWrite(denseUnpack(run), t);
        }
        run = denseRunAt(pixel);
      }
      uint color = colors[i / 4u][i % 4u];
      run.r += color & 0x00FF00FFu; // red and blue
      run.g += (color >> 8) & 0xFFu;
      run.n += 1u;
      run.near = min(run.near, depth);
      run.far = max(run.far, depth);
    }
    run = denseUnpack(run);
    // Joining across lanes. A lane's first run continues the open run on its left (the previous lane's last
    // run, or the carry for lane 0) if they share the pixel. A lane with a single run passes the open run on,
    // one with several closes it into its head. Segmented inclusive scan of the open runs; bit 31 of `key`
    // (the pixel otherwise: framebuffers hold under 2^31 pixels) says that the run reaches further left.
    bool several = head.pixel != kNoPixel;
    uint firstPixel = several ? head.pixel : run.pixel;
    uint leftPixel = subgroupShuffleUp(run.pixel, 1u);
    bool join = firstPixel == (lane == 0u ? carry.pixel : leftPixel);
    DenseRun open = run;
    uint key = run.pixel | (!several && join ? 0x80000000u : 0u);
    for (uint d = 1u; d < size; d *= 2u) {
      uint leftKey = subgroupShuffleUp(key, d);
      DenseRun left = DenseRun(0u, subgroupShuffleUp(open.r, d), subgroupShuffleUp(open.g, d),
                               subgroupShuffleUp(open.b, d), subgroupShuffleUp(open.n, d),
                               subgroupShuffleUp(open.near, d), subgroupShuffleUp(open.far, d));
      if (lane >= d && key >= 0x80000000u) {
        open = denseJoin(left, open);
        key = (key & 0x7FFFFFFFu) | (leftKey & 0x80000000u);
      }
    }
    if (key >= 0x80000000u) open = denseJoin(carry, open); // reaches back through lane 0 to the carry
    DenseRun incoming = denseShuffleUp(open, 1u);
    if (lane == 0u) incoming = carry;
    if (several && join) head = denseJoin(incoming, head);
    bool nextJoins = subgroupShuffleDown(uint(join), 1u) != 0u;
    // Writes: the carry if lane 0 did not continue it, every head, every open run the next lane does not
    // continue; the last lane's open run is the next step's carry.
    if (lane == 0u && !join && carry.pixel != kNoPixel) writes += denseWrite(carry, t);
    if (several) writes += denseWrite(head, t);
    if (lane + 1u < size && !nextJoins) writes += denseWrite(open, t);
    carry = denseShuffle(open, size - 1u);
  }
  if (lane == 0u && carry.pixel != kNoPixel) writes += denseWrite(carry, t);
  return writes;
}

// Whether a tile of the pixel rectangle of a dense batch (v) holds a pixel that hqs_dense_check.comp flagged:
// only then must the accumulation pass draw the batch again. Call in uniform control flow, by every thread
// of the workgroup.
shared uint denseFlaggedTiles;
bool denseBatchFlagged(BatchView v, uint64_t tiles, uint tilesX) {
  if (gl_LocalInvocationIndex == 0u) denseFlaggedTiles = 0u;
  barrier();
  uvec4 r = uvec4(v.rect) / kHqsDenseTile;
  uint across = r.z - r.x + 1u, count = across * (r.w - r.y + 1u);
  for (uint k = gl_LocalInvocationIndex; k < count; k += kPointGroupSize)
    if (UintArray(tiles).v[(r.y + k / across) * tilesX + r.x + k % across] != 0u) denseFlaggedTiles = 1u;
  barrier();
  return denseFlaggedTiles != 0u;
}

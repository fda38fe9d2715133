// Blending for high-quality splatting, shared by hqs, hqs1r and batch-hqs: subgroup aggregation, then the
// atomics of either accumulator layout. Needs the subgroup basic/vote/ballot/arithmetic/shuffle extensions
// and common.inc.glsl (and GL_EXT_control_flow_attributes).
//
// Contention decides the speed of HQS: in a dense overview every pixel blends hundreds of points, and
// consecutive points (Morton or scan order) mostly share a few pixels. So a thread first adds its four
// consecutive points per pixel (hqsMergeFour), then lanes add within the subgroup, one round per distinct pixel (a ballot picks the lowest pending lane, every lane
// on its pixel adds to it), for at most kHqsRounds pixels; lanes still pending after that add alone. One
// atomic (hqs1r) or two (hqs) per distinct pixel of a subgroup's 4 x 32 points instead of one or two per point. On the H200
// this beat VK_NV_shader_subgroup_partitioned by far (docs/performance.md), and it runs on every device.

// Distinct pixels a subgroup combines before the rest add alone: bounds the rounds where a subgroup's points
// scatter (shuffled orders), while ordered clouds rarely have more pixels per subgroup.
const uint kHqsRounds = 4u;

// Workgroups launched one after another run at the same time, and in an ordered cloud they would draw
// neighbouring points into the same pixels: their atomics would queue on the same accumulator words. So the
// accumulation passes hand workgroup g the chunk (g % 16) * (n / 16) + g / 16 of the n chunks (the last n % 16
// keep their place): workgroups running together draw chunks a sixteenth of the part apart. On the H200 this
// took hqs1r from 8.4 to 7.0 ms on a 796 M Morton overview, with the same atomics (docs/performance.md).
const uint kHqsInterleave = 16u;
uint hqsInterleavedChunk(uint group, uint groups) {
  uint per = groups / kHqsInterleave;
  return group < per * kHqsInterleave ? (group % kHqsInterleave) * per + group / kHqsInterleave : group;
}

// The single-atomic layout of the 2022 paper (hqs1r, batch-hqs; resolved by resolve_hqs.comp with
// ONE_ROUND = 1): acc holds one uint64_t per pixel packing r, g, b, count in 16 bits each, exact up to 255
// points (255 x 255 < 2^16), then two 32-bit-per-channel fallback words per pixel for later points:
// packed words [0, pixels), then (r << 32 | g, b << 32 | count) pairs.
void hqsAccumulate(Uint64Array acc, uint pixels, uint pixel, uint r, uint g, uint b, uint count) {
  // count <= 255 bounds r, g, b by 255 x 255: the packed fields cannot carry into each other.
  if (count <= kHqs1rMaxCount) {
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
  }
  atomicAdd(acc.v[pixels + 2 * pixel], (uint64_t(r) << 32) | uint64_t(g));
  atomicAdd(acc.v[pixels + 2 * pixel + 1], (uint64_t(b) << 32) | uint64_t(count));
}

// The two-atomic layout of the 2019 paper (hqs): acc holds (r << 32 | g, b << 32 | count) per pixel.
void hqsAccumulateTwo(Uint64Array acc, uint pixel, uint r, uint g, uint b, uint count) {
  atomicAdd(acc.v[2 * pixel], (uint64_t(r) << 32) | uint64_t(g));
  atomicAdd(acc.v[2 * pixel + 1], (uint64_t(b) << 32) | uint64_t(count));
}

// Sums over the lanes of the subgroup: every lane brings the sums of the points it blends into `pixel`
// (0xFFFFFFFF: none; at most kHqsLanePoints points) and leaves with `writes` set if it is to add the sums it
// then holds. Call in uniform control flow.
//
// A round's sums are two subgroup adds, not four: r | g << 16 and b | count << 16. A subgroup of up to 64
// lanes with up to 4 points each sums at most 64 x 4 x 255 = 65,280 per field, so the 16-bit fields never
// carry into each other; wider subgroups (none known) take the four 32-bit adds. Subgroup adds are the
// bulk of the rounds' work on NVIDIA (docs/performance.md, "HQS: what the accumulation pass spends").
const uint kHqsLanePoints = 4u;
void hqsSubgroupSums(uint pixel, inout uint r, inout uint g, inout uint b, inout uint count, out bool writes) {
  bool pending = pixel != 0xFFFFFFFFu;
  writes = false;
  bool packed = gl_SubgroupSize * kHqsLanePoints * 255u <= 0xFFFFu;
  uint lo = packed ? r | (g << 16) : r, hi = packed ? b | (count << 16) : b;
  for (uint round = 0u; round < kHqsRounds && subgroupAny(pending); ++round) {
    uint leader = subgroupBallotFindLSB(subgroupBallot(pending));
    uint leaderPixel = subgroupShuffle(pixel, leader);
    bool mine = pending && pixel == leaderPixel;
    bool lead = gl_SubgroupInvocationID == leader;
    uint slo = subgroupAdd(mine ? lo : 0u), shi = subgroupAdd(mine ? hi : 0u);
    lo = lead ? slo : lo;
    hi = lead ? shi : hi;
    if (!packed) {
      uint sg = subgroupAdd(mine ? g : 0u), sc = subgroupAdd(mine ? count : 0u);
      g = lead ? sg : g;
      count = lead ? sc : count;
    }
    writes = writes || lead;
    pending = pending && !mine;
  }
  writes = writes || pending; // past kHqsRounds pixels: alone
  r = packed ? lo & 0xFFFFu : lo;
  g = packed ? lo >> 16 : g;
  b = packed ? hi & 0xFFFFu : hi;
  count = packed ? hi >> 16 : count;
}

// A thread's four consecutive points, which often share a pixel: the sums of a pixel go to its first entry
// and the entries left are moved to the front, so that entries 1-3 are empty in most lanes of an ordered
// cloud and their subgroup step (hqsBlend) is skipped as a whole. Empty entries have pixel 0xFFFFFFFF and
// zero sums.
void hqsMergeFour(inout uint pixel[4], inout uint r[4], inout uint g[4], inout uint b[4], inout uint n[4]) {
  [[unroll]] for (uint k = 1u; k < 4u; ++k) {
    [[unroll]] for (uint e = 0u; e < k; ++e) {
      if (pixel[k] != 0xFFFFFFFFu && pixel[k] == pixel[e]) {
        r[e] += r[k];
        g[e] += g[k];
        b[e] += b[k];
        n[e] += n[k];
        pixel[k] = 0xFFFFFFFFu;
      }
    }
  }
  uint outPixel[4], outR[4], outG[4], outB[4], outN[4];
  [[unroll]] for (uint o = 0u; o < 4u; ++o) {
    outPixel[o] = 0xFFFFFFFFu;
    outR[o] = outG[o] = outB[o] = outN[o] = 0u;
  }
  uint kept = 0u;
  [[unroll]] for (uint k = 0u; k < 4u; ++k) {
    if (pixel[k] == 0xFFFFFFFFu) continue;
    // Constant indices only (a dynamic index would put the arrays in local memory).
    [[unroll]] for (uint o = 0u; o <= k; ++o) {
      if (o == kept) {
        outPixel[o] = pixel[k];
        outR[o] = r[k];
        outG[o] = g[k];
        outB[o] = b[k];
        outN[o] = n[k];
      }
    }
    ++kept;
  }
  pixel = outPixel;
  r = outR;
  g = outG;
  b = outB;
  n = outN;
}

// Blends one group of points per lane (`pixel` 0xFFFFFFFF: none; r, g, b, count their sums) into the
// accumulators: the single-atomic layout if oneRound, else the two-atomic one. Call in uniform control flow;
// a subgroup with nothing to blend returns at once.
void hqsBlend(Uint64Array acc, uint pixels, bool oneRound, uint pixel, uint r, uint g, uint b, uint count) {
  if (!subgroupAny(pixel != 0xFFFFFFFFu)) return; // uniform: no lane blends
  bool writes;
  hqsSubgroupSums(pixel, r, g, b, count, writes);
  if (!writes) return;
  if (oneRound)
    hqsAccumulate(acc, pixels, pixel, r, g, b, count);
  else
    hqsAccumulateTwo(acc, pixel, r, g, b, count);
}

// The channel sums of one RGBA8 color.
void hqsChannels(uint color, out uint r, out uint g, out uint b) {
  r = color & 0xFFu;
  g = (color >> 8) & 0xFFu;
  b = (color >> 16) & 0xFFu;
}

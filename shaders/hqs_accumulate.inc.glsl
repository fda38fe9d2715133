// Blending for high-quality splatting, shared by hqs, hqs1r, batch-hqs and lod-hqs: subgroup aggregation, a
// workgroup table in shared memory, then the atomics of either accumulator layout. Needs the subgroup
// basic/vote/ballot/arithmetic/shuffle extensions, common.inc.glsl, and a workgroup of kPointGroupSize.
//
// Contention decides the speed of HQS: in a dense overview every pixel blends hundreds of points, and the
// lanes of a subgroup (consecutive points in Morton or scan order) mostly share a few pixels. So lanes first
// add within the subgroup, one round per distinct pixel (a ballot picks the lowest pending lane, every lane
// on its pixel adds to it), for at most kHqsRounds pixels; lanes still pending after that add alone. One
// atomic (hqs1r) or two (hqs) per distinct pixel of a subgroup instead of one or two per point. On the H200
// this beat VK_NV_shader_subgroup_partitioned by far (bench/NOTES.md), and it runs on every device.
//
// In Morton order a pixel's points are also consecutive across subgroups: at an overview the subgroups of a
// workgroup, and of workgroups on other SMs, add to the same few words at the same moment, which serializes
// at the L2 slice that holds them. So the subgroups' sums go to a table in shared memory first (pixel ->
// r, g, b, count), and each of the workgroup's pixels reaches the accumulators once, when the workgroup
// ends. The table is small and bounded (see kHqsTableSlots): a pixel that finds no place in it adds to the
// accumulators at once, as it would without the table, so a scattered view pays a few shared operations
// per point and no more. The sums are integers, so the resolved image is the same however they are grouped.

// Distinct pixels a subgroup combines before the rest add alone: bounds the rounds where a subgroup's points
// scatter (shuffled orders), while ordered clouds rarely have more pixels per subgroup.
const uint kHqsRounds = 4u;

// The single-atomic layout of the 2022 paper (hqs1r, batch-hqs; resolved by resolve_hqs.comp with
// ONE_ROUND = 1): acc holds one uint64_t per pixel packing r, g, b, count in 16 bits each, exact up to 255
// points (255 x 255 < 2^16), then two 32-bit-per-channel fallback words per pixel for later points:
// packed words [0, pixels), then (r << 32 | g, b << 32 | count) pairs.
// Returns the atomics it made (statistics).
uint hqsAccumulate(Uint64Array acc, uint pixels, uint pixel, uint r, uint g, uint b, uint count) {
  uint atomics = 0u;
  // count <= 255 bounds r, g, b by 255 x 255: the packed fields cannot carry into each other.
  if (count <= kHqs1rMaxCount) {
    uint64_t packed = uint64_t(r) | (uint64_t(g) << 16) | (uint64_t(b) << 32) | (uint64_t(count) << 48);
    // A pixel already full (as a plain read shows it) goes to the fallback sums at once: in dense views
    // thousands of points share a pixel, and the add-then-take-back pair below would put two atomics per
    // point on one hot address. The read may count adds that are about to be taken back; such a point then
    // uses the fallback although it might have fitted, which changes nothing in the resolved sums.
    if (uint(acc.v[pixel] >> 48) + count <= kHqs1rMaxCount) {
      uint64_t before = atomicAdd(acc.v[pixel], packed);
      if (uint(before >> 48) + count <= kHqs1rMaxCount) return 1u;
      // The word would pass 255 points: take the add back (modular addition undoes exactly, whatever
      // carries happened meanwhile) and add to the 32-bit fallback sums instead. Adds that stay always saw
      // a total of at most 255 including themselves, so the packed fields never overflow in the final sums.
      atomicAdd(acc.v[pixel], -packed);
      atomics = 2u;
    }
  }
  atomicAdd(acc.v[pixels + 2 * pixel], (uint64_t(r) << 32) | uint64_t(g));
  atomicAdd(acc.v[pixels + 2 * pixel + 1], (uint64_t(b) << 32) | uint64_t(count));
  return atomics + 2u;
}

// The two-atomic layout of the 2019 paper (hqs): acc holds (r << 32 | g, b << 32 | count) per pixel.
uint hqsAccumulateTwo(Uint64Array acc, uint pixel, uint r, uint g, uint b, uint count) {
  atomicAdd(acc.v[2 * pixel], (uint64_t(r) << 32) | uint64_t(g));
  atomicAdd(acc.v[2 * pixel + 1], (uint64_t(b) << 32) | uint64_t(count));
  return 2u;
}

// Either layout: the single-atomic one if oneRound. Returns the atomics made.
uint hqsAccumulateAny(Uint64Array acc, uint pixels, bool oneRound, uint pixel, uint r, uint g, uint b,
                      uint count) {
  return oneRound ? hqsAccumulate(acc, pixels, pixel, r, g, b, count)
                  : hqsAccumulateTwo(acc, pixel, r, g, b, count);
}

// ---- The workgroup table: open addressing with linear probing, keys claimed by compare-and-swap and never
// removed, so a pixel present in the table lies before the first empty slot of its probe sequence.

// 2^9 = 512 slots x 5 words = 10 KiB of shared memory per workgroup: on an H200 (228 KiB per SM) sixteen
// 128-thread workgroups still fit, as many as its 2,048 threads allow. A 10,240-point batch of a Morton
// overview covers some tens of pixels, a 512-point hqs1r workgroup at most 512.
const uint kHqsTableBits = 9u;
const uint kHqsTableSlots = 1u << kHqsTableBits;
// Pixels taken before the table closes to new ones: at half load a probe sequence ends at an empty slot
// after ~2.5 slots (linear probing), so a closed table turns a new pixel away quickly. Lanes racing past the
// limit can take at most one workgroup's threads more, 3/4 of the slots.
const uint kHqsTableOpenSlots = kHqsTableSlots / 2u;
// Slots a pixel looks at before adding to the accumulators directly: bounds the work of the unlucky.
const uint kHqsTableProbes = 8u;

shared uint hqsTableKey[kHqsTableSlots]; // pixel, or kNoPixel for an empty slot
shared uint hqsTableR[kHqsTableSlots];   // 32-bit sums: at most 255 x the workgroup's points each
shared uint hqsTableG[kHqsTableSlots];
shared uint hqsTableB[kHqsTableSlots];
shared uint hqsTableCount[kHqsTableSlots];
shared uint hqsTableTaken; // slots claimed

// First, by every thread of the workgroup in uniform control flow.
void hqsTableClear() {
  for (uint s = gl_LocalInvocationIndex; s < kHqsTableSlots; s += kPointGroupSize) {
    hqsTableKey[s] = kNoPixel;
    hqsTableR[s] = 0u;
    hqsTableG[s] = 0u;
    hqsTableB[s] = 0u;
    hqsTableCount[s] = 0u;
  }
  if (gl_LocalInvocationIndex == 0u) hqsTableTaken = 0u;
  memoryBarrierShared();
  barrier();
}

// Adds the sums to the pixel's slot; false if the pixel found none (the table closed or its probes ran out).
bool hqsTableAdd(uint pixel, uint r, uint g, uint b, uint count) {
  // Fibonacci hashing: neighbouring pixels (a Morton run covers a small square of them) land far apart.
  uint slot = (pixel * 0x9E3779B9u) >> (32u - kHqsTableBits);
  for (uint probe = 0u; probe < kHqsTableProbes; ++probe) {
    // A plain read first: a key, once set, never changes, and an empty slot read stale is settled by the
    // compare-and-swap below.
    uint key = hqsTableKey[slot];
    if (key == kNoPixel) {
      if (hqsTableTaken >= kHqsTableOpenSlots) return false; // closed, and the pixel is not before this slot
      key = atomicCompSwap(hqsTableKey[slot], kNoPixel, pixel);
      if (key == kNoPixel) {
        atomicAdd(hqsTableTaken, 1u);
        key = pixel;
      }
    }
    if (key == pixel) {
      atomicAdd(hqsTableR[slot], r);
      atomicAdd(hqsTableG[slot], g);
      atomicAdd(hqsTableB[slot], b);
      atomicAdd(hqsTableCount[slot], count);
      return true;
    }
    slot = (slot + 1u) & (kHqsTableSlots - 1u);
  }
  return false;
}

// Last, by every thread of the workgroup in uniform control flow after its last hqsBlend: adds each pixel of
// the table to the accumulators. Returns the atomics this thread made.
uint hqsTableFlush(Uint64Array acc, uint pixels, bool oneRound) {
  memoryBarrierShared();
  barrier();
  uint atomics = 0u;
  for (uint s = gl_LocalInvocationIndex; s < kHqsTableSlots; s += kPointGroupSize) {
    uint pixel = hqsTableKey[s];
    if (pixel != kNoPixel)
      atomics += hqsAccumulateAny(acc, pixels, oneRound, pixel, hqsTableR[s], hqsTableG[s], hqsTableB[s],
                                  hqsTableCount[s]);
  }
  return atomics;
}

// Sums over the lanes of the subgroup: every lane brings the sums of the points it blends into `pixel`
// (0xFFFFFFFF: none) and leaves with `writes` set if it is to add the sums it then holds. Call in uniform
// control flow. Sums stay in 32 bits (a subgroup has at most 128 lanes).
void hqsSubgroupSums(uint pixel, inout uint r, inout uint g, inout uint b, inout uint count, out bool writes) {
  bool pending = pixel != 0xFFFFFFFFu;
  writes = false;
  for (uint round = 0u; round < kHqsRounds && subgroupAny(pending); ++round) {
    uint leader = subgroupBallotFindLSB(subgroupBallot(pending));
    uint leaderPixel = subgroupShuffle(pixel, leader);
    bool mine = pending && pixel == leaderPixel;
    uint sr = subgroupAdd(mine ? r : 0u), sg = subgroupAdd(mine ? g : 0u);
    uint sb = subgroupAdd(mine ? b : 0u), sc = subgroupAdd(mine ? count : 0u);
    bool lead = gl_SubgroupInvocationID == leader;
    r = lead ? sr : r;
    g = lead ? sg : g;
    b = lead ? sb : b;
    count = lead ? sc : count;
    writes = writes || lead;
    pending = pending && !mine;
  }
  writes = writes || pending; // past kHqsRounds pixels: alone
}

// Blends one group of points per lane (`pixel` 0xFFFFFFFF: none; r, g, b, count their sums) into the
// workgroup's table, or where it has no room into the accumulators: the single-atomic layout if oneRound,
// else the two-atomic one. Call in uniform control flow, between hqsTableClear and hqsTableFlush; a subgroup
// with nothing to blend returns at once. Returns the atomics made on the accumulators.
uint hqsBlend(Uint64Array acc, uint pixels, bool oneRound, uint pixel, uint r, uint g, uint b, uint count) {
  if (!subgroupAny(pixel != 0xFFFFFFFFu)) return 0u; // uniform: no lane blends
  bool writes;
  hqsSubgroupSums(pixel, r, g, b, count, writes);
  if (!writes || hqsTableAdd(pixel, r, g, b, count)) return 0u;
  return hqsAccumulateAny(acc, pixels, oneRound, pixel, r, g, b, count);
}

// The channel sums of one RGBA8 color.
void hqsChannels(uint color, out uint r, out uint g, out uint b) {
  r = color & 0xFFu;
  g = (color >> 8) & 0xFFu;
  b = (color >> 16) & 0xFFu;
}

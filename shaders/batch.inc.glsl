// The 2022 batched rasterizer (Schuetz, Kerbl, Wimmer, "Software Rasterization of 2 Billion Points in Real
// Time", sections 4-5), shared by its passes. One workgroup of 128 threads draws one batch of 10240
// consecutive points of a part (BatchPush pc): it frustum-culls the batch's box, chooses how many of the
// three coordinate words its points need (cloud/batch_words.h has the bit layout), and decodes points
// relative to the batch's min corner. Points are projected by project.inc.glsl, like the 2021 methods.
//
// Every thread computes the batch decision from the same loads with the same instructions, so the decision
// is uniform over the workgroup without shared memory or a barrier.
#include "common.inc.glsl"
#include "project.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
layout(push_constant) uniform Push { BatchPush pc; };

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer BoundsArray {
  BatchBounds v[];
};
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Uvec4Array { uvec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer FrameRef { BatchFrame f; };

const uint kNoPixel = 0xFFFFFFFFu;

// Margin of the culling tests, relative to the sum of the absolute terms of a clip coordinate: the float
// rounding of projecting (and of decoding) a point stays below a few ulps of that sum (2^-23 each), far
// under 1e-5, so no test on the box drops a point that the per-point test would keep.
const float kCullMargin = 1e-5;

// What a workgroup decided about its batch.
struct BatchView {
  uint words;   // coordinate words its points load: 1..3; 0 = culled
  vec3 base;  // the centre of the batch's first cell, relative to the scene origin: min corner + centre steps
  vec3 scale; // size / (2^30 - 1): units per quantization step
};

BatchView viewBatch(uint batch, uint width, uint height, uint forcedWords, bool culling) {
  BatchBounds bounds = BoundsArray(pc.bounds).v[batch];
  vec3 lo = bounds.min.xyz, hi = bounds.max.xyz, size = hi - lo;
  mat4 m = pc.viewProj;
  // Clip coordinates of the eight corners: the min corner plus any of the three edge vectors.
  vec4 c0 = m * vec4(lo, 1.0), ex = m[0] * size.x, ey = m[1] * size.y, ez = m[2] * size.z;
  vec3 a = max(abs(lo), abs(hi));
  vec4 e = kCullMargin * (abs(m[0]) * a.x + abs(m[1]) * a.y + abs(m[2]) * a.z + abs(m[3]));
  // Outside a clip plane: all corners beyond it. A point is kept if near < w and -w <= x < w, -w < y <= w.
  bool left = true, right = true, below = true, above = true, behind = true, nearOrBehind = false;
  float wMin = 3.0e38;
  vec2 ndcMax = vec2(0.0);
  for (uint k = 0u; k < 8u; ++k) {
    vec4 c = c0;
    if ((k & 1u) != 0u) c += ex;
    if ((k & 2u) != 0u) c += ey;
    if ((k & 4u) != 0u) c += ez;
    left = left && c.x + c.w < -(e.x + e.w);
    right = right && c.x - c.w > e.x + e.w;
    below = below && c.y + c.w < -(e.y + e.w);
    above = above && c.y - c.w > e.y + e.w;
    behind = behind && c.w + e.w < pc.nearW;
    nearOrBehind = nearOrBehind || c.w - e.w <= pc.nearW;
    wMin = min(wMin, c.w - e.w);
    ndcMax = max(ndcMax, abs(c.xy) / c.w);
  }
  BatchView v;
  v.scale = size * (1.0 / float(kBatchCoordinateMax));
  v.words = 3u;
  if (forcedWords != 0u) {
    v.words = forcedWords;
  } else if (!nearOrBehind) {
    // Moving a point by d changes x/w by (dx - (x/w) dw) / w', w' its new depth (>= wMin, the box's least),
    // so its pixel moves by at most W/2 (|row x| + max|x/w| |row w|) |d| / wMin, max|x/w| over the box
    // being that over its corners (x/w is quasi-linear where w > 0) and at most 1 for a visible point;
    // likewise in y. Decoding from k of the 3 words moves a point by at most |size| 2^-(10k+1) (half a
    // cell). The fewest words whose bound stays under half a pixel: a point moves by at most one pixel.
    vec3 rx = vec3(m[0].x, m[1].x, m[2].x), ry = vec3(m[0].y, m[1].y, m[2].y);
    vec3 rw = vec3(m[0].w, m[1].w, m[2].w);
    vec2 slope = min(ndcMax, vec2(1.0));
    float perUnit = max(0.5 * float(width) * (length(rx) + slope.x * length(rw)),
                        0.5 * float(height) * (length(ry) + slope.y * length(rw))) / wMin;
    float pixels = perUnit * length(size) * 1.001; // 1.001: the 30-bit rounding (2^-31) and float slack
    v.words = pixels * (1.0 / 2048.0) < 0.5 ? 1u : pixels * (1.0 / 2097152.0) < 0.5 ? 2u : 3u;
  }
  // The cell-centre rule of decodeBatchWords: half the range of the unknown low bits, in steps.
  float centre = v.words == 1u ? 524288.0 : v.words == 2u ? 512.0 : 0.0; // 2^19, 2^9, 0
  v.base = lo + centre * v.scale;
  if (culling && (left || right || below || above || behind)) v.words = 0u;
  return v;
}

// The three 10-bit fields of a coordinate word (x in bits 0-9, y 10-19, z 20-29) as floats. Each field is
// put into the mantissa of 2^23 and 2^23 subtracted, which is exact below 2^23: three integer ops and a
// float add instead of int-to-float conversions, which run at a quarter of the float rate on NVIDIA GPUs
// (16 per clock and multiprocessor on Hopper), and the 1G-point overview decodes 3 G fields a frame.
vec3 tenBitFields(uint word) {
  return uintBitsToFloat((uvec3(word, word >> 10, word >> 20) & 0x3FFu) | 0x4B000000u) - 8388608.0;
}

// A point from its first v.words words (the others are ignored), relative to the scene origin: the batch's
// min corner plus the cell centre plus each word's fields in its own step (2^20, 2^10 and 1 quantization
// steps), one fused multiply-add per word and axis.
vec3 decodePoint(BatchView v, uint high, uint medium, uint low) {
  vec3 p = v.base + tenBitFields(high) * (v.scale * 1048576.0);
  if (v.words >= 2u) p += tenBitFields(medium) * (v.scale * 1024.0);
  if (v.words >= 3u) p += tenBitFields(low) * v.scale;
  return p;
}

// Statistics (shared.h, kStat*): a thread counts in a register, the workgroup sums in shared memory, and
// one thread adds the sums to the workgroup's row of the statistics buffer.
shared uint groupCount;

// First thing in main(), by every thread.
void beginStats() {
  if (gl_LocalInvocationIndex == 0u) groupCount = 0u;
  barrier();
}

// Last thing in main(), by every thread: `mine` adds to counter `counter`; with `batchCounts` the batch is
// counted too (processed; rendered and its points by precision unless v.words == 0).
void endStats(uint64_t statsAddress, uint counter, uint mine, bool batchCounts, uint words, uint count) {
  if (mine != 0u) atomicAdd(groupCount, mine);
  barrier();
  if (gl_LocalInvocationIndex != 0u) return;
  Uint64Array stats = Uint64Array(statsAddress);
  uint row = (gl_WorkGroupID.x % kBatchStatSlots) * kBatchStatCount;
  if (groupCount != 0u) atomicAdd(stats.v[row + counter], uint64_t(groupCount));
  if (!batchCounts) return;
  atomicAdd(stats.v[row + kStatBatchesProcessed], 1ul);
  if (words == 0u) return;
  atomicAdd(stats.v[row + kStatBatchesRendered], 1ul);
  atomicAdd(stats.v[row + kStatPointsOneWord + words - 1u], uint64_t(count));
}

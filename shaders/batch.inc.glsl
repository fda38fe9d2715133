// The 2022 batched rasterizer (Schuetz, Kerbl, Wimmer, "Software Rasterization of 2 Billion Points in Real
// Time", sections 4-5): what every pass of a box of quantized points shares, whatever holds the box. A batch
// of 10240 consecutive points of a part (batch_part.inc.glsl) is one such box, an octree node of the LOD
// methods (lod.inc.glsl) another. The box is frustum-culled, its points load as many of the three
// coordinate words as its projected size needs (cloud/batch_words.h has the bit layout) and are decoded
// relative to its min corner. Points are projected by project.inc.glsl, like the 2021 methods.
//
// A box decision (viewBox) depends only on the box and the camera, so it is computed once per box, by a
// pass before the drawing: batch_views.comp for the batches of a part (batch_part.inc.glsl), the node pass
// for octree nodes (lod.inc.glsl). Every thread of a drawing workgroup reads the same bits.
#extension GL_KHR_shader_subgroup_basic : require
#include "common.inc.glsl"
#include "clip.inc.glsl"
#include "project.inc.glsl"

layout(local_size_x = kPointGroupSize) in;
// 1: the pass draws a stereo frame, every box's points into both eyes' halves of the framebuffer (BatchFrame,
// LodFrame: eyes); the drawing loops read each point's words once and project them twice.
layout(constant_id = 2) const uint STEREO = 0;


// Margin of the culling tests, relative to the sum of the absolute terms of a clip coordinate: the float
// rounding of projecting (and of decoding) a point stays below a few ulps of that sum (2^-23 each), far
// under 1e-5, so no test on the box drops a point that the per-point test would keep.
const float kCullMargin = 1e-5;

// How a batch's points reach the screen: the first word gives 1 + f/1024 per axis (f the 10-bit field,
// exact in a float's mantissa), further words add theirs 2^-10 and 2^-20 lower; call that sum g. A point's
// position is then an affine function of g, and so are the three homogeneous screen coordinates
//   X = W/2 (c.x + c.w),  Y = H/2 (c.w - c.y),  Z = c.w,   pixel (X/Z, Y/Z)   (project.inc.glsl's contract),
// so the workgroup folds the batch's origin, quantization step, view-projection and viewport into one
// 3x4 map, and a point costs 9 fused multiply-adds and one reciprocal. Every batch pass projects through
// it, so all of them put a point on the same pixel. A three-word (full precision) point is the exception:
// its g would round away the last 6 of its 30 bits, so it is decoded to its position the way the 2021
// methods' floats are and projected by project.inc.glsl, which puts it where they do (ties of equal depth
// and pixel borders included: the full-precision tests compare winners pixel by pixel).
// The map yields X/Z - 1/2, and adding 1.5 x 2^23 rounds that to the nearest integer in the mantissa:
// floor(X/Z) except where X/Z is an odd integer exactly (then one less), one full-rate add where a
// float-to-int conversion is a quarter-rate instruction on NVIDIA GPUs (1.5 % faster on the H200:
// docs/performance.md).

// What a workgroup decided about its batch.
struct BatchView {
  uint words;  // coordinate words its points load: 1..3; 0 = culled
  bool inside; // every point of the box projects in front of the near plane and inside the image
  bool clipTest; // the clip volumes keep some of the box's points: each is tested (at full precision)
  vec3 cx, cy, cz; // screen map: X = cx.x g.x + cx.y g.y + cx.z g.z + offset.x; Y, Z likewise
  vec3 offset;
  vec3 lo, step; // the batch's min corner (relative to the scene origin) and 2^30 quantization steps
  vec4 rect;     // batch-hqs's dense batches: the pixels its points can land on (first column, first row, last
                 // column, last row); x < 0: not a dense batch (denseRect, batch_part.inc.glsl)
};

// The camera of a batch pass: view-projection relative to the scene origin, near plane, image size, and
// where the image lies in the framebuffer: pixel (x, y) is element offset + y * pitch + x (a stereo eye is
// one half of a framebuffer twice as wide; a mono image has pitch = width, offset 0).
struct BatchCamera {
  mat4 viewProj; // only rows x, y, w are used
  float nearW;   // points with c.w <= nearW are dropped
  uint width;
  uint height;
  uint pitch;
  uint offset;
};

// The decision for the box [lo, hi] (relative to the scene origin): forcedWords 1..3 overrides the
// adaptive precision; without culling no box is culled.
BatchView viewBox(vec3 lo, vec3 hi, BatchCamera cam, uint forcedWords, bool culling) {
  vec3 size = hi - lo;
  mat4 m = cam.viewProj;
  // Clip coordinates of the eight corners: the min corner plus any of the three edge vectors.
  vec4 c0 = m * vec4(lo, 1.0), ex = m[0] * size.x, ey = m[1] * size.y, ez = m[2] * size.z;
  vec3 a = max(abs(lo), abs(hi));
  vec4 e = kCullMargin * (abs(m[0]) * a.x + abs(m[1]) * a.y + abs(m[2]) * a.z + abs(m[3]));
  // Outside a clip plane: all corners beyond it. A point is kept if near < w and -w <= x < w, -w < y <= w.
  // Inside: all corners within every plane by the margin, so every point of the box is, whatever the
  // rounding of its projection.
  bool left = true, right = true, below = true, above = true, behind = true, nearOrBehind = false;
  bool inside = true;
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
    behind = behind && c.w + e.w < cam.nearW;
    nearOrBehind = nearOrBehind || c.w - e.w <= cam.nearW;
    inside = inside && c.x + c.w > e.x + e.w && c.w - c.x > e.x + e.w && c.y + c.w > e.y + e.w &&
             c.w - c.y > e.y + e.w;
    wMin = min(wMin, c.w - e.w);
    ndcMax = max(ndcMax, abs(c.xy) / c.w);
  }
  BatchView v;
  vec3 scale = size * (1.0 / float(kBatchCoordinateMax)); // units per quantization step
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
    float perUnit = max(0.5 * float(cam.width) * (length(rx) + slope.x * length(rw)),
                        0.5 * float(cam.height) * (length(ry) + slope.y * length(rw))) / wMin;
    float pixels = perUnit * length(size) * 1.001; // 1.001: the 30-bit rounding (2^-31) and float slack
    v.words = pixels * (1.0 / 2048.0) < 0.5 ? 1u : pixels * (1.0 / 2097152.0) < 0.5 ? 2u : 3u;
  }
  v.inside = inside && !nearOrBehind;
  // The cell-centre rule of decodeBatchWords: half the range of the unknown low bits, in steps. A point
  // sits at lo + (q + centre) scale, q its 30-bit coordinate, and q = 2^30 (g - k) with k = 1, 1 + 2^-10
  // or 1 + 2^-10 + 2^-20 for 1, 2, 3 words: at (lo + centre scale - k step) + g step, step = 2^30 scale.
  float centre = v.words == 1u ? 524288.0 : v.words == 2u ? 512.0 : 0.0; // 2^19, 2^9, 0
  float k = v.words == 1u ? 1.0 : v.words == 2u ? 1.0 + 1.0 / 1024.0 : 1.0 + 1.0 / 1024.0 + 1.0 / 1048576.0;
  vec3 step = scale * 1073741824.0;
  vec4 origin = vec4(lo + centre * scale - k * step, 1.0);
  // Screen rows of the map; X and Y lose Z/2 so that X/Z is the pixel's x - 1/2.
  vec4 rowW = vec4(m[0].w, m[1].w, m[2].w, m[3].w);
  vec4 rowX = 0.5 * float(cam.width) * (vec4(m[0].x, m[1].x, m[2].x, m[3].x) + rowW) - 0.5 * rowW;
  vec4 rowY = 0.5 * float(cam.height) * (rowW - vec4(m[0].y, m[1].y, m[2].y, m[3].y)) - 0.5 * rowW;
  v.cx = rowX.xyz * step;
  v.cy = rowY.xyz * step;
  v.cz = rowW.xyz * step;
  v.offset = vec3(dot(rowX, origin), dot(rowY, origin), dot(rowW, origin));
  v.lo = lo;
  v.step = step;
  v.rect = vec4(-1.0);
  v.clipTest = false;
  if (culling && (left || right || below || above || behind)) v.words = 0u;
  return v;
}

// The clip volumes of the box being drawn (ClipVolumes address): the includer defines it (the part's scene's for
// a batch, the octree's for a node).
uint64_t boxClip();

// The clip's decision on top of viewBox's for the box [lo, hi]: a box whose points the clip volumes all drop
// is culled (`clipped`: it was not culled by the frustum), one they keep in part loads all three words and
// tests each point's exact position (the position the 2021 methods test, so every method keeps the same points).
BatchView clipView(BatchView v, vec3 lo, vec3 hi, out bool clipped) {
  clipped = false;
  v.clipTest = false;
  if (v.words == 0u) return v;
  uint verdict = clipBoxVerdict(boxClip(), lo, hi);
  if (verdict == kClipBoxNone) {
    v.words = 0u;
    clipped = true;
  } else if (verdict == kClipBoxSome) {
    v.clipTest = true;
    v.words = 3u; // whatever the precision: the map of fewer words is left unused (fullPrecisionPosition)
  }
  return v;
}

// A box decision in a buffer (shared.h, LodNodeView), for passes that read it instead of computing it. cy.w
// holds the flags: 1 inside, 2 clipTest.
LodNodeView storeView(BatchView v) {
  float flags = (v.inside ? 1.0 : 0.0) + (v.clipTest ? 2.0 : 0.0);
  return LodNodeView(vec4(v.cx, uintBitsToFloat(v.words)), vec4(v.cy, flags), vec4(v.cz, v.rect.x),
                     vec4(v.offset, v.rect.y), vec4(v.lo, v.rect.z), vec4(v.step, v.rect.w));
}

BatchView loadView(LodNodeView s) {
  BatchView v;
  v.words = floatBitsToUint(s.cx.w);
  uint flags = uint(s.cy.w);
  v.inside = (flags & 1u) != 0u;
  v.clipTest = (flags & 2u) != 0u;
  v.cx = s.cx.xyz;
  v.cy = s.cy.xyz;
  v.cz = s.cz.xyz;
  v.offset = s.offset.xyz;
  v.lo = s.lo.xyz;
  v.step = s.step.xyz;
  v.rect = vec4(s.cz.w, s.offset.w, s.lo.w, s.step.w);
  return v;
}

// 1 + f/1024 for the three 10-bit fields f of a coordinate word (x in bits 0-9, y 10-19, z 20-29): each
// field is moved to the top of a float's mantissa under the exponent of 1. Two integer ops a field and no
// int-to-float conversion, which runs at a quarter of the float rate on NVIDIA GPUs.
vec3 wordFields(uint word) {
  return uintBitsToFloat((uvec3(word << 13, word << 3, word >> 7) & 0x7FE000u) | 0x3F800000u);
}

// g of a point from its first `words` words (the others are ignored); exact for one and two words, within
// 2^-24 of the batch for three.
vec3 pointFields(uint words, uint high, uint medium, uint low) {
  vec3 g = wordFields(high);
  if (words >= 2u) g = fma(wordFields(medium), vec3(1.0 / 1024.0), g);
  if (words >= 3u) g = fma(wordFields(low), vec3(1.0 / 1048576.0), g);
  return g;
}

// Homogeneous screen coordinates (X, Y, Z) of a point with fields g.
vec3 screenOf(BatchView v, vec3 g) {
  return vec3(fma(g.z, v.cx.z, fma(g.y, v.cx.y, fma(g.x, v.cx.x, v.offset.x))),
              fma(g.z, v.cy.z, fma(g.y, v.cy.y, fma(g.x, v.cy.x, v.offset.y))),
              fma(g.z, v.cz.z, fma(g.y, v.cz.y, fma(g.x, v.cz.x, v.offset.z))));
}

// The pixel column or row of X/Z - 1/2 = s, for a value known to lie in the image, plus kRoundingBias: the
// bits of s + 1.5 x 2^23. That sum lies in [2^23, 2^24), where floats are the integers, for any s in
// (-2^22, 2^22) (2^23 alone would put s in (-1/2, 0) below 2^23, where the step is 1/2), and its bits are
// kRoundingBias + the rounded s.
const uint kRoundingBias = 0x4B400000u; // floatBitsToUint(12582912.0)
uint biasedPixelCoordinate(float s) {
  return floatBitsToUint(s + 12582912.0);
}

// The pixel and depth bits of a point of an `inside` batch: no test can fail. The clamp only keeps a
// rounding surprise inside the framebuffer (whatever the coordinates, the index stays in it).
void projectInside(vec3 s, BatchCamera cam, out uint pixel, out uint depthBits) {
  float r = 1.0 / s.z;
  // (row - bias) pitch + (column - bias) = row pitch + column - bias (pitch + 1), mod 2^32 like the index
  // itself: the camera's constant replaces a subtraction per coordinate (the same bits, clamp included).
  uint index = biasedPixelCoordinate(s.y * r) * cam.pitch + biasedPixelCoordinate(s.x * r) -
               kRoundingBias * (cam.pitch + 1u);
  pixel = cam.offset + min(index, cam.pitch * (cam.height - 1u) + cam.width - 1u);
  depthBits = floatBitsToUint(s.z);
}

// The same with project.inc.glsl's tests: false for a point behind the near plane or outside the image.
bool projectChecked(vec3 s, BatchCamera cam, out uint pixel, out uint depthBits) {
  pixel = kNoPixel; // out parameters are written on every path (see projectPoint)
  depthBits = 0xFFFFFFFFu;
  if (!(s.z > cam.nearW)) return false; // also drops NaN
  uint width = cam.width, height = cam.height;
  float r = 1.0 / s.z;
  float x = s.x * r, y = s.y * r;
  // Compare as floats before rounding (x, y are the pixel's coordinates less 1/2): a huge or NaN
  // coordinate must not wrap into the image.
  if (!(x >= -0.5 && x < float(width) - 0.5 && y >= -0.5 && y < float(height) - 0.5)) return false;
  projectInside(s, cam, pixel, depthBits);
  return true;
}

// The position of a point from all three words, relative to the scene origin: the min corner plus each
// word's fields in its own step (2^20, 2^10 and 1 quantization steps; g - 1 and the steps are exact).
vec3 fullPrecisionPosition(BatchView v, uint high, uint medium, uint low) {
  vec3 p = v.lo + (wordFields(high) - 1.0) * v.step;
  p += (wordFields(medium) - 1.0) * (v.step * (1.0 / 1024.0));
  return p + (wordFields(low) - 1.0) * (v.step * (1.0 / 1048576.0));
}

// The pixel and depth bits of a point of batch v decoded from `words` words (a constant where the caller
// can make it one). `checked`: with the near-plane and image tests (false only for an `inside` batch).
bool projectBatchPoint(BatchView v, uint words, bool checked, uint high, uint medium, uint low, BatchCamera cam,
                       out uint pixel, out uint depthBits) {
  if (words == 3u) {
    vec3 p = fullPrecisionPosition(v, high, medium, low);
    if (v.clipTest && !clipKeeps(boxClip(), p)) {
      pixel = kNoPixel;
      depthBits = 0xFFFFFFFFu;
      return false;
    }
    return projectPointInto(cam.viewProj, p, cam.width, cam.height, cam.pitch, cam.offset, cam.nearW, pixel,
                            depthBits);
  }
  vec3 s = screenOf(v, pointFields(words, high, medium, low));
  if (checked) return projectChecked(s, cam, pixel, depthBits);
  projectInside(s, cam, pixel, depthBits);
  return true;
}

// The pixels of the image that the points of a box v (decided for camera cam) can land on, as the rectangle
// (first column, first row, last column, last row); x = -1 if not known (a box not inside the image). Every
// point's fields g lie in [1, 2.002)^3 (1 + f/1024 for the first word, lower words add under 2^-9), so its
// screen coordinates are the map of a point of that cube; X/Z and Y/Z, quasi-linear where Z > 0, take their
// extremes at its corners. A point's pixel rounds its own X/Z - 1/2, a few ulps from the corners' bound: one
// pixel of margin covers that.
vec4 boxPixelRect(BatchView v, BatchCamera cam) {
  if (v.words == 0u || !v.inside) return vec4(-1.0);
  vec2 lo = vec2(3.0e38), hi = vec2(-3.0e38);
  for (uint k = 0u; k < 8u; ++k) {
    vec3 g = vec3((k & 1u) != 0u ? 2.002 : 1.0, (k & 2u) != 0u ? 2.002 : 1.0, (k & 4u) != 0u ? 2.002 : 1.0);
    vec3 s = screenOf(v, g);
    if (!(s.z > 0.0)) return vec4(-1.0);
    vec2 p = s.xy / s.z;
    lo = min(lo, p);
    hi = max(hi, p);
  }
  vec2 last = vec2(float(cam.width - 1u), float(cam.height - 1u));
  return vec4(clamp(floor(lo) - 1.0, vec2(0.0), last), clamp(ceil(hi) + 1.0, vec2(0.0), last));
}

// Where the points of a box are: the addresses of its first point's word in each word buffer (16-byte
// aligned, padded to a multiple of 4 points) and of its first point's RGBA8 color.
struct BatchWords {
  uint64_t high;   // bits 29..20 of x | y << 10 | z << 20
  uint64_t medium; // bits 19..10
  uint64_t low;    // bits 9..0
  uint64_t colors;
};

// The words of the box's points 4g .. 4g + 3 (uvec4 g of each word buffer), the first `words` of them;
// zeros for the others.
void loadQuad(BatchWords at, uint g, uint words, out uvec4 high, out uvec4 medium, out uvec4 low) {
  high = Uvec4Array(at.high).v[g];
  medium = words >= 2u ? Uvec4Array(at.medium).v[g] : uvec4(0u);
  low = words >= 3u ? Uvec4Array(at.low).v[g] : uvec4(0u);
}

// Statistics (shared.h, kStat*): a thread counts in a register, the workgroup sums in shared memory, and
// one thread adds the sums to the workgroup's row of the statistics buffer. COUNT 0: nothing is counted
// (the pipelines of frames whose counts nobody reads: the shared sum and its two barriers cost ~5 % of
// batch-prefetch's frame on an H200).
layout(constant_id = 5) const uint COUNT = 1;
shared uint groupCount, groupCount2;

// First thing in main(), by every thread.
void beginStats() {
  if (COUNT == 0u) return;
  if (gl_LocalInvocationIndex == 0u) groupCount = groupCount2 = 0u;
  barrier();
}

// Last thing in main(), by every thread: `mine` adds to counter `counter`, `mine2` to `counter2`; with
// `batchCounts` the batch is counted too (processed; rendered and its points by precision unless
// v.words == 0).
void endStatsOf2(uint64_t statsAddress, uint counter, uint mine, uint counter2, uint mine2, bool batchCounts,
                 uint words, uint count) {
  if (COUNT == 0u) return;
  if (mine != 0u) atomicAdd(groupCount, mine);
  if (mine2 != 0u) atomicAdd(groupCount2, mine2);
  barrier();
  if (gl_LocalInvocationIndex != 0u) return;
  Uint64Array stats = Uint64Array(statsAddress);
  uint row = (gl_WorkGroupID.x % kBatchStatSlots) * kBatchStatCount;
  if (groupCount != 0u) atomicAdd(stats.v[row + counter], uint64_t(groupCount));
  if (groupCount2 != 0u) atomicAdd(stats.v[row + counter2], uint64_t(groupCount2));
  if (!batchCounts) return;
  atomicAdd(stats.v[row + kStatBatchesProcessed], 1ul);
  if (words == 0u) return;
  atomicAdd(stats.v[row + kStatBatchesRendered], 1ul);
  atomicAdd(stats.v[row + kStatPointsOneWord + words - 1u], uint64_t(count));
}

void endStats(uint64_t statsAddress, uint counter, uint mine, bool batchCounts, uint words, uint count) {
  endStatsOf2(statsAddress, counter, mine, counter, 0u, batchCounts, words, count);
}

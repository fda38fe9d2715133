#include "cloud/batch_words.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>

namespace pointrast {

namespace {

// Rounds t = (value - min) / size * kBatchCoordinateMax to the nearest integer, halves away from zero
// (std::llround), clamped to [0, max], for a size > 0. Without branches: a branch on the fraction is taken
// at random and mispredicted half the time, which made the encoding several times slower. Below 0 gives
// 0, as rounding first and clamping after would; inside the range the fraction t - trunc(t) is exact.
inline uint32_t quantize(double value, double min, double size) {
  double t = (value - min) / size * double(kBatchCoordinateMax);
  t = t > 0 ? t : 0.0;
  t = t < double(kBatchCoordinateMax) ? t : double(kBatchCoordinateMax);
  const auto whole = uint32_t(t); // truncates
  return whole + uint32_t(t - double(whole) >= 0.5);
}

// Four points at a time, their twelve coordinates side by side (x y z x y z ...) in three vectors of four
// lanes: lane l of vector j is axis (4j + l) % 3. The same arithmetic as quantize(), lane by lane, in
// vector registers (three divisions of four doubles, not twelve of one); an axis without extent has size 1
// and keep 0. Where the CPU has AVX2 its clone runs (without FMA, whose single rounding would change
// results; the vector types lower to SSE2 pairs elsewhere).
using Double4 = double __attribute__((vector_size(32)));
using Int4 = int32_t __attribute__((vector_size(16)));
using Long4 = int64_t __attribute__((vector_size(32)));

struct Lanes {
  Double4 scale[3], offset[3], min[3], size[3];
  Int4 keep[3];
};

__attribute__((target_clones("avx2", "default"))) void quantizeGroups(const int32_t* p, uint64_t groups,
                                                                      const Lanes& c, uint32_t* q) {
  constexpr double kMax = double(kBatchCoordinateMax);
  const Double4 zero = {0, 0, 0, 0}, max = {kMax, kMax, kMax, kMax}, half = {0.5, 0.5, 0.5, 0.5};
  constexpr int64_t kOneBits = 0x3FF0000000000000; // the bits of 1.0
  for (uint64_t g = 0; g < groups; ++g)
    for (int j = 0; j < 3; ++j) {
      Int4 raw;
      std::memcpy(&raw, p + 12 * g + 4 * j, sizeof raw);
      Double4 t =
          (__builtin_convertvector(raw, Double4) * c.scale[j] + c.offset[j] - c.min[j]) / c.size[j] * max;
      t = t > zero ? t : zero;
      t = t < max ? t : max;
      // The whole part (the conversion truncates; t <= kMax < 2^31), plus one where the fraction is a half
      // or more: added as doubles (exact for these integers), so that the comparison's 64-bit mask needs no
      // narrowing to 32-bit lanes.
      const Double4 whole = __builtin_convertvector(__builtin_convertvector(t, Int4), Double4);
      const Long4 up = (t - whole >= half) & Long4{kOneBits, kOneBits, kOneBits, kOneBits};
      Double4 rounded;
      std::memcpy(&rounded, &up, sizeof rounded); // 1.0 or 0.0
      const Int4 r = __builtin_convertvector(whole + rounded, Int4) & c.keep[j];
      std::memcpy(q + 12 * g + 4 * j, &r, sizeof r);
    }
}

uint32_t axis(uint32_t word, int a) {
  return (word >> (10 * a)) & ((1u << kBatchWordBits) - 1);
}

} // namespace

void encodeBatchWords(uint32_t* high, uint32_t* medium, uint32_t* low, const PointCloud& cloud,
                      const Batch& batch) {
  const glm::dvec3 min = batch.bounds.min, size = batch.bounds.size();
  const bool extent[3] = {size.x > 0, size.y > 0, size.z > 0}; // an axis without extent quantizes to 0
  const int32_t* p = cloud.positions.data() + 3 * batch.first;
  const glm::dvec3 scale = cloud.scale, offset = cloud.offset;
  constexpr uint32_t kMask = (1u << kBatchWordBits) - 1;
  const uint32_t count = batch.count; // read once: the words written could alias the batch
  Lanes lanes;
  for (int l = 0; l < 12; ++l) {
    const int a = l % 3, j = l / 4, i = l % 4;
    lanes.scale[j][i] = scale[a];
    lanes.offset[j][i] = offset[a];
    lanes.min[j][i] = min[a];
    lanes.size[j][i] = extent[a] ? size[a] : 1.0;
    lanes.keep[j][i] = extent[a] ? -1 : 0;
  }
  // Blocks of 64 points (256 coordinates of a thread's stack), the last partial group of four one by one.
  constexpr uint32_t kBlock = 64;
  uint32_t block[3 * kBlock];
  const uint32_t whole = count / 4 * 4;
  for (uint32_t k0 = 0; k0 < whole; k0 += kBlock) {
    const uint32_t n = std::min(kBlock, whole - k0);
    quantizeGroups(p + 3 * uint64_t(k0), n / 4, lanes, block);
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t x = block[3 * i], y = block[3 * i + 1], z = block[3 * i + 2], k = k0 + i;
      high[k] = (x >> 20 & kMask) | (y >> 20 & kMask) << 10 | (z >> 20 & kMask) << 20;
      medium[k] = (x >> 10 & kMask) | (y >> 10 & kMask) << 10 | (z >> 10 & kMask) << 20;
      low[k] = (x & kMask) | (y & kMask) << 10 | (z & kMask) << 20;
    }
  }
  for (uint32_t k = whole; k < count; ++k) {
    uint32_t q[3];
    for (int a = 0; a < 3; ++a) // world(): the position as double, times the scale, plus the offset
      q[a] = extent[a] ? quantize(p[3 * k + a] * scale[a] + offset[a], min[a], size[a]) : 0;
    high[k] = (q[0] >> 20 & kMask) | (q[1] >> 20 & kMask) << 10 | (q[2] >> 20 & kMask) << 20;
    medium[k] = (q[0] >> 10 & kMask) | (q[1] >> 10 & kMask) << 10 | (q[2] >> 10 & kMask) << 20;
    low[k] = (q[0] & kMask) | (q[1] & kMask) << 10 | (q[2] & kMask) << 20;
  }
}

glm::dvec3 decodeBatchWords(const Batch& batch, uint32_t high, uint32_t medium, uint32_t low, int words) {
  assert(words >= 1 && words <= 3);
  const uint32_t known = kBatchWordBits * uint32_t(words);
  glm::dvec3 result;
  for (int a = 0; a < 3; ++a) {
    uint32_t q =
        axis(high, a) << 20 | (words >= 2 ? axis(medium, a) << 10 : 0) | (words >= 3 ? axis(low, a) : 0);
    // The unknown low bits: take the centre of the cell they span.
    double centre = known < kBatchCoordinateBits ? double(1u << (kBatchCoordinateBits - known)) * 0.5 : 0.0;
    double t = (double(q) + centre) / double(kBatchCoordinateMax);
    result[a] = batch.bounds.min[a] + t * batch.bounds.size()[a];
  }
  return result;
}

glm::dvec3 batchWordsError(const Batch& batch, int words) {
  double cell =
      std::ldexp(1.0, int(kBatchCoordinateBits - kBatchWordBits * uint32_t(words))) / kBatchCoordinateMax;
  return batch.bounds.size() * (0.5 * cell + 1.0 / kBatchCoordinateMax);
}

} // namespace pointrast

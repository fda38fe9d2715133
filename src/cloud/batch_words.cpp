#include "cloud/batch_words.h"

#include <algorithm>
#include <cassert>
#include <cmath>

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
  for (uint32_t k = 0; k < count; ++k) {
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

#include "cloud/batch_words.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace pointrast {

namespace {

// Rounds t to the nearest integer, halves away from zero (std::llround), clamped to [0, max]; inline, as
// a library call per axis was most of the encoding's time. Below 0 (and NaN) gives 0, as rounding first
// and clamping after would; inside the range the fraction t - trunc(t) is exact.
uint32_t quantize(double value, double min, double size) {
  if (!(size > 0)) return 0;
  const double t = (value - min) / size * double(kBatchCoordinateMax);
  if (!(t > 0)) return 0;
  if (t >= double(kBatchCoordinateMax)) return kBatchCoordinateMax;
  const auto whole = uint32_t(t); // truncates
  return t - double(whole) >= 0.5 ? whole + 1 : whole;
}

// Bits [shift, shift + 10) of the three axes packed as x | y << 10 | z << 20.
uint32_t pack(const uint32_t q[3], uint32_t shift) {
  constexpr uint32_t kMask = (1u << kBatchWordBits) - 1;
  return ((q[0] >> shift) & kMask) | (((q[1] >> shift) & kMask) << 10) | (((q[2] >> shift) & kMask) << 20);
}

uint32_t axis(uint32_t word, int a) {
  return (word >> (10 * a)) & ((1u << kBatchWordBits) - 1);
}

} // namespace

void encodeBatchWords(uint32_t* high, uint32_t* medium, uint32_t* low, const PointCloud& cloud,
                      const Batch& batch) {
  const glm::dvec3 min = batch.bounds.min, size = batch.bounds.size();
  for (uint32_t k = 0; k < batch.count; ++k) {
    glm::dvec3 p = cloud.world(batch.first + k);
    uint32_t q[3] = {quantize(p.x, min.x, size.x), quantize(p.y, min.y, size.y),
                     quantize(p.z, min.z, size.z)};
    high[k] = pack(q, 20);
    medium[k] = pack(q, 10);
    low[k] = pack(q, 0);
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

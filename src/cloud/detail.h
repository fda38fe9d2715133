// Helpers shared by the files of src/cloud/, not part of the library's interface.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>

#include "cloud/cloud.h"

namespace pointrast::detail {

// Per-axis extremes of quantized positions. Kept as integers so a merge is exact and cheap; the world
// bounds follow from the two corners because q * scale + offset is monotonic in q.
struct QuantBox {
  int32_t min[3] = {std::numeric_limits<int32_t>::max(), std::numeric_limits<int32_t>::max(),
                    std::numeric_limits<int32_t>::max()};
  int32_t max[3] = {std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::min(),
                    std::numeric_limits<int32_t>::min()};

  bool empty() const { return min[0] > max[0]; }
  void expand(const QuantBox& b) {
    for (int a = 0; a < 3; ++a) {
      min[a] = std::min(min[a], b.min[a]);
      max[a] = std::max(max[a], b.max[a]);
    }
  }
};

// Serial scan of points [first, first + count) of a positions array (3 int32 per point).
QuantBox quantBox(const int32_t* positions, uint64_t first, uint64_t count);
// The same over all points, on all hardware threads.
QuantBox quantBoxParallel(const int32_t* positions, uint64_t count);

// World bounds of the points a box was taken from, computed exactly as PointCloud::world() would.
Bounds worldBounds(const QuantBox& box, const glm::dvec3& scale, const glm::dvec3& offset);

// Spreads the low 21 bits of v so that bit k lands on bit 3k. Each step halves the group width:
//   0x1f00000000ffff   groups of 16 bits, 48 apart   ---- ---- ---1 1111 (x32)  ...  1111 1111 1111 1111
//   0x1f0000ff0000ff   groups of  8 bits, 24 apart
//   0x100f00f00f00f00f groups of  4 bits, 12 apart
//   0x10c30c30c30c30c3 groups of  2 bits,  6 apart
//   0x1249249249249249 single bits,        3 apart   ...1 0010 0100 1001 = bit 0, 3, 6, 9, ...
inline uint64_t spreadBits3(uint32_t v) {
  uint64_t x = v & 0x1fffffu;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// spreadBits3 of every 7-bit value, for code pieces of at most 7 bits (a histogram cell of the octree
// builder: one load per axis instead of five shift-or-mask steps).
struct Spread7Table {
  uint32_t value[128];
  constexpr Spread7Table() : value() {
    for (uint32_t v = 0; v < 128; ++v) {
      uint32_t x = 0;
      for (int b = 0; b < 7; ++b)
        x |= ((v >> b) & 1u) << (3 * b);
      value[v] = x;
    }
  }
};
inline constexpr Spread7Table kSpread7{};

// The inverse of spreadBits3: bits 0, 3, 6, ... of v gathered into the low 21 bits.
inline uint32_t compactBits3(uint64_t v) {
  uint64_t x = v & 0x1249249249249249ull;
  x = (x | x >> 2) & 0x10c30c30c30c30c3ull;
  x = (x | x >> 4) & 0x100f00f00f00f00full;
  x = (x | x >> 8) & 0x1f0000ff0000ffull;
  x = (x | x >> 16) & 0x1f00000000ffffull;
  x = (x | x >> 32) & 0x1fffffull;
  return static_cast<uint32_t>(x);
}

// splitmix64 (Steele, Lea, Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014): the
// state advances by the golden-ratio increment and each output is the state through a bijective mixer,
// so output number i (from 0) for a seed is splitmixMix(seed + (i + 1) * kSplitmixGamma). Fully
// specified here, so random orders and scenes are the same with every compiler and standard library.
constexpr uint64_t kSplitmixGamma = 0x9E3779B97F4A7C15ull;
constexpr uint64_t splitmixMix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
constexpr uint64_t splitmixAt(uint64_t seed, uint64_t i) {
  return splitmixMix(seed + (i + 1) * kSplitmixGamma);
}

// A perceptual rainbow ("Turbo", Mikhailov 2019, polynomial fit) for t in [0, 1], as packRgba.
uint32_t rampColor(double t);

} // namespace pointrast::detail

// Small synthetic clouds for the cloud-layer tests.
#pragma once

#include <cstdint>
#include <random>

#include "cloud/cloud.h"

namespace pointrast::testing {

// n points with coordinates uniform in [-range, range] quantization steps, scale 1 mm, the given offset.
// std::mt19937_64 itself is fully specified by the standard, so the raw draws are portable.
inline PointCloud randomCloud(uint64_t n, int32_t range = 1'000'000, glm::dvec3 offset = glm::dvec3(0),
                              uint64_t seed = 7) {
  PointCloud cloud;
  cloud.offset = offset;
  cloud.positions.resize(3 * n);
  std::mt19937_64 rng(seed);
  const uint64_t span = 2 * uint64_t(range) + 1;
  for (auto& q : cloud.positions)
    q = static_cast<int32_t>(int64_t(rng() % span) - range);
  computeBounds(cloud);
  return cloud;
}

} // namespace pointrast::testing

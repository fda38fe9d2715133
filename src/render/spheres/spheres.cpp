#include "render/spheres/spheres.h"

#include <cmath>
#include <mutex>

#include "base/parallel.h"

namespace pointrast {

Bounds sphereSetBounds(const ParticleSet& set) {
  std::mutex mutex;
  Bounds result;
  parallelBlocks(set.size(), 1 << 18, [&](uint64_t, uint64_t begin, uint64_t end) {
    Bounds local;
    for (uint64_t i = begin; i < end; ++i) {
      glm::dvec3 p(set.xyz[3 * i], set.xyz[3 * i + 1], set.xyz[3 * i + 2]);
      double r = set.radiusOf(i);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !(r > 0) || !std::isfinite(r))
        continue;
      local.expand(p - r);
      local.expand(p + r);
    }
    std::lock_guard lock(mutex);
    result.expand(local);
  });
  if (!result.empty()) {
    result.min += set.origin;
    result.max += set.origin;
  }
  return result;
}

} // namespace pointrast

#include "cloud/particles.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "base/parallel.h"
#include "cloud/detail.h"

namespace pointrast {

namespace {

// 1 M particles per block, as for point clouds: thread start-up is noise, 2..128 cores stay balanced.
constexpr uint64_t kBlock = uint64_t(1) << 20;

// Per-axis extremes of relative float positions. The world bounds follow exactly, because
// origin + double(f) is monotonic in f.
struct FloatBox {
  float min[3] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                  std::numeric_limits<float>::infinity()};
  float max[3] = {-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                  -std::numeric_limits<float>::infinity()};
};

} // namespace

void computeBounds(ParticleSet& set) {
  const uint64_t n = set.size();
  std::vector<FloatBox> boxes((n + kBlock - 1) / kBlock);
  parallelBlocks(n, kBlock, [&](uint64_t block, uint64_t begin, uint64_t end) {
    FloatBox box;
    for (uint64_t i = begin; i < end; ++i)
      for (int a = 0; a < 3; ++a) {
        box.min[a] = std::min(box.min[a], set.xyz[3 * i + a]);
        box.max[a] = std::max(box.max[a], set.xyz[3 * i + a]);
      }
    boxes[block] = box;
  });
  Bounds bounds;
  for (const FloatBox& box : boxes) {
    bounds.expand(set.origin + glm::dvec3(box.min[0], box.min[1], box.min[2]));
    bounds.expand(set.origin + glm::dvec3(box.max[0], box.max[1], box.max[2]));
  }
  set.bounds = bounds;
}

Bounds sphereBounds(const ParticleSet& set) {
  // Computed from the particles, not from set.bounds, so a set built by hand needs no computeBounds().
  const uint64_t n = set.size();
  std::vector<Bounds> boxes((n + kBlock - 1) / kBlock);
  parallelBlocks(n, kBlock, [&](uint64_t block, uint64_t begin, uint64_t end) {
    Bounds box;
    for (uint64_t i = begin; i < end; ++i) {
      const glm::dvec3 p(set.xyz[3 * i], set.xyz[3 * i + 1], set.xyz[3 * i + 2]);
      const double r = set.radiusOf(i);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !(r > 0) || !std::isfinite(r))
        continue; // no renderer draws it
      box.expand(p - r);
      box.expand(p + r);
    }
    boxes[block] = box;
  });
  Bounds bounds;
  for (const Bounds& b : boxes)
    bounds.expand(b);
  if (!bounds.empty()) {
    bounds.min += set.origin;
    bounds.max += set.origin;
  }
  return bounds;
}

RadiusRange radiusRange(const ParticleSet& set) {
  if (!set.perParticleRadius()) return {set.globalRadius, set.globalRadius};
  if (set.radius.empty()) return {};
  auto [lo, hi] = std::minmax_element(set.radius.begin(), set.radius.end());
  return {*lo, *hi};
}

uint32_t particleRamp(double t) {
  return detail::rampColor(t);
}

ParticleSet particlesFromCloud(const PointCloud& cloud, float radius) {
  assert(std::isfinite(radius) && radius > 0);
  const uint64_t n = cloud.size();
  ParticleSet set;
  set.source = cloud.source;
  set.origin = cloud.origin();
  set.globalRadius = radius;
  set.xyz.resize(3 * n);
  set.colors.resize(n);
  // Both run on all hardware threads for large clouds.
  toRelativeFloat(set.xyz.data(), cloud, 0, n, set.origin);
  displayColors(set.colors.data(), cloud, 0, n);
  // From the float positions, not cloud.bounds: the set's world(i) is what the bounds must enclose.
  computeBounds(set);
  return set;
}

} // namespace pointrast

#include "render/pick.h"

#include <bit>
#include <cmath>
#include <limits>
#include <mutex>

#include "base/parallel.h"
#include "gpu/shared_types.h"
#include "render/scene.h"

namespace pointrast {

std::optional<uint64_t> pickPoint(const PickRequest& r, uint32_t x, uint32_t y, uint64_t word) {
  if (word == shared::kEmptyPixel || !r.cloud || r.width == 0 || r.height == 0) return std::nullopt;
  const PointCloud& cloud = *r.cloud;
  const glm::dvec3 origin = cloud.origin();
  const glm::dmat4 vp = viewProjection(r.camera, origin, double(r.width) / double(r.height));
  const double nearW = r.camera.nearW > 0 ? r.camera.nearW : defaultNear(cloud.bounds);
  const bool int40 = r.depth == DepthMode::Int40;
  const uint32_t colorMask = int40 ? 0xFFFFFFu : 0xFFFFFFFFu;
  const uint32_t wordColor = uint32_t(word) & colorMask;
  const double wordDepth = int40 ? 0.0 : double(std::bit_cast<float>(uint32_t(word >> 32)));
  const bool clipDrops = r.filter && r.filter->hasClip() && r.filter->clipMode != ClipMode::Highlight;
  std::mutex mutex;
  uint64_t best = UINT64_MAX;
  double bestScore = std::numeric_limits<double>::infinity();
  parallelBlocks(cloud.size(), 1 << 16, [&](uint64_t, uint64_t begin, uint64_t end) {
    uint64_t mine = UINT64_MAX;
    double mineScore = std::numeric_limits<double>::infinity();
    for (uint64_t i = begin; i < end; ++i) {
      // The float the GPU holds, then the projection in double: a pixel border may round either way, so
      // the 3 x 3 pixels around the picked one are candidates and the word decides.
      const glm::dvec3 world = cloud.world(i);
      const glm::dvec3 p = glm::dvec3(glm::vec3(world - origin));
      const glm::dvec4 c = vp * glm::dvec4(p, 1.0);
      if (!(c.w > nearW)) continue;
      const double fx = (c.x / c.w + 1) * 0.5 * r.width, fy = (1 - c.y / c.w) * 0.5 * r.height;
      if (!(std::abs(fx - (x + 0.5)) < 1.5 && std::abs(fy - (y + 0.5)) < 1.5)) continue;
      if (clipDrops && insideClip(*r.filter, world) != (r.filter->clipMode == ClipMode::Inside)) continue;
      uint32_t color = 0;
      displayColors(&color, cloud, i, 1, r.colors);
      if (r.filter) highlightColors(&color, cloud, i, 1, *r.filter);
      if ((color & colorMask) != wordColor) continue;
      // Float depth: nearest the word's; int40 (steps of an unknown scale): the closest point.
      const double score = int40 ? c.w : std::abs(c.w - wordDepth);
      if (score < mineScore) {
        mineScore = score;
        mine = i;
      }
    }
    std::lock_guard lock(mutex);
    if (mineScore < bestScore || (mineScore == bestScore && mine < best)) {
      bestScore = mineScore;
      best = mine;
    }
  });
  if (best == UINT64_MAX) return std::nullopt;
  return best;
}

} // namespace pointrast

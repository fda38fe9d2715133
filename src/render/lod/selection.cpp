#include "render/lod/selection.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <queue>

#include "gpu/shared_types.h"

namespace pointrast::lod {

namespace {

// Cubes are tested grown by this fraction of their edge: a source's points may sit a quantum outside their
// node's cube (PotreeConverter truncates coordinates), and a node kept wrongly costs only its GPU culling.
constexpr double kCubeMargin = 1e-3;

struct Candidate {
  double weight;
  NodeKey key;
  uint32_t id;
  // The priority queue's top is the largest: larger weight first, then the smaller key.
  bool operator<(const Candidate& o) const {
    if (weight != o.weight) return weight < o.weight;
    return o.key < key;
  }
};

} // namespace

uint64_t pagesOf(uint64_t points) {
  return (points + shared::kLodPagePoints - 1) / shared::kLodPagePoints;
}

double projectedRadiusPx(const Bounds& cube, const Camera& camera, uint32_t height) {
  const double radius = 0.5 * cube.diagonal();
  const double distance = glm::length(cube.center() - camera.eye);
  if (distance <= radius) return std::numeric_limits<double>::infinity();
  return radius * double(height) / (2.0 * distance * std::tan(glm::radians(camera.fovY) / 2.0));
}

double foveationFactor(const Foveation& foveation, double distance) {
  if (!foveation.enabled || distance <= foveation.radius) return 1.0;
  const double t = std::min(1.0, (distance - foveation.radius) / std::max(1e-9, 1.0 - foveation.radius));
  return 1.0 + (foveation.periphery - 1.0) * t;
}

double foveatedSizePx(const Bounds& cube, const Camera& camera, const glm::dmat4& viewProj,
                      const glm::dvec3& origin, uint32_t width, uint32_t height, const Foveation& foveation) {
  const double size = projectedRadiusPx(cube, camera, height);
  if (!foveation.enabled || std::isinf(size)) return size;
  const glm::dvec4 c = viewProj * glm::dvec4(cube.center() - origin, 1.0);
  if (!(c.w > 0)) return size; // behind the eye yet visible: the eye is near, keep the fovea's threshold
  const glm::dvec2 pixel{(c.x / c.w + 1.0) * 0.5 * width, (1.0 - c.y / c.w) * 0.5 * height};
  const glm::dvec2 centre{0.5 * width, 0.5 * height};
  const double halfDiagonal = 0.5 * std::sqrt(double(width) * width + double(height) * height);
  const double distance = std::max(0.0, glm::length(pixel - centre) - size) / halfDiagonal;
  return size / foveationFactor(foveation, distance);
}

bool boxMayBeVisible(const Bounds& box, const glm::dmat4& viewProj, const glm::dvec3& origin, double nearW) {
  bool left = true, right = true, below = true, above = true, behind = true;
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 corner{i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y,
                      i & 4 ? box.max.z : box.min.z};
    glm::dvec4 c = viewProj * glm::dvec4(corner - origin, 1.0);
    left = left && c.x < -c.w;
    right = right && c.x > c.w;
    below = below && c.y < -c.w;
    above = above && c.y > c.w;
    behind = behind && c.w <= nearW;
  }
  return !(left || right || below || above || behind);
}

Selection selectNodes(const Hierarchy& hierarchy, std::span<const Camera> cameras, uint32_t width,
                      uint32_t height, const glm::dvec3& origin, double nearW, const SelectionLimits& limits) {
  assert(!cameras.empty() && cameras.size() <= 2);
  const OctreeMetadata& meta = hierarchy.metadata();
  glm::dmat4 viewProj[2];
  for (size_t k = 0; k < cameras.size(); ++k)
    viewProj[k] = viewProjection(cameras[k], origin, double(width) / double(height));
  auto grown = [&](const NodeKey& key) {
    Bounds cube = meta.nodeCube(key);
    glm::dvec3 margin(kCubeMargin * (cube.max.x - cube.min.x));
    margin = glm::max(margin, 2.0 * meta.scale);
    cube.min -= margin;
    cube.max += margin;
    return cube;
  };
  auto visible = [&](const Bounds& box) {
    for (size_t k = 0; k < cameras.size(); ++k)
      if (boxMayBeVisible(box, viewProj[k], origin, nearW)) return true;
    return false;
  };
  // The node's size in the eyes that may see it (-1: none): each eye's selection taken alone is then a
  // subset of the stereo one, and without budgets or foveation the stereo selection is exactly their union
  // (a child is then never visible, nor larger, where its parent is not).
  auto weigh = [&](const NodeKey& key) {
    const Bounds box = grown(key), cube = meta.nodeCube(key);
    double size = -1;
    for (size_t k = 0; k < cameras.size(); ++k)
      if (boxMayBeVisible(box, viewProj[k], origin, nearW))
        size = std::max(
            size, foveatedSizePx(cube, cameras[k], viewProj[k], origin, width, height, limits.foveation));
    return size;
  };
  Selection s;
  std::priority_queue<Candidate> queue;
  const NodeKey root = hierarchy.node(0).info.key;
  if (visible(grown(root))) queue.push({std::numeric_limits<double>::infinity(), root, 0});
  while (!queue.empty()) {
    const Candidate c = queue.top();
    queue.pop();
    const HostNode& node = hierarchy.node(c.id);
    const uint64_t points = node.info.pointCount, pages = pagesOf(points);
    if ((limits.pointBudget && s.points + points > limits.pointBudget) ||
        (limits.pageBudget && s.pages + pages > limits.pageBudget)) {
      s.limited = true;
      break;
    }
    s.nodes.push_back(c.id);
    s.points += points;
    s.pages += pages;
    if (!node.childrenKnown) {
      s.unexpanded.push_back(c.id);
      continue;
    }
    for (uint32_t k = 0; k < node.childCount; ++k) {
      const uint32_t child = node.firstChild + k;
      const NodeKey key = hierarchy.node(child).info.key;
      const double size = weigh(key);
      if (size < 0 || size < limits.minNodePx) continue; // outside every frustum, or too small
      queue.push({size, key, child});
    }
  }
  return s;
}

Selection shareOf(const Selection& selection, const Hierarchy& hierarchy, uint32_t index, uint32_t shares) {
  assert(shares > 0 && index < shares && "a share of the selection");
  std::vector<uint32_t> nodes;
  for (uint32_t id : selection.nodes)
    if (hierarchy.node(id).info.pointCount > 0) nodes.push_back(id);
  std::sort(nodes.begin(), nodes.end(),
            [&](uint32_t a, uint32_t b) { return hierarchy.node(a).info.key < hierarchy.node(b).info.key; });
  uint64_t total = 0;
  for (uint32_t id : nodes)
    total += hierarchy.node(id).info.pointCount;
  Selection share;
  share.limited = selection.limited;
  // Node i is in run floor(shares * before / total), in 128-bit arithmetic: billions of points times
  // thousands of shares cannot overflow.
  unsigned __int128 before = 0;
  for (uint32_t id : nodes) {
    const uint64_t points = hierarchy.node(id).info.pointCount;
    const uint64_t run = uint64_t(std::min<unsigned __int128>(before * shares / total, shares - 1));
    before += points;
    if (run != index) continue;
    share.nodes.push_back(id);
    share.points += points;
    share.pages += pagesOf(points);
  }
  return share;
}

} // namespace pointrast::lod

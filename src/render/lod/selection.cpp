#include "render/lod/selection.h"

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

Selection selectNodes(const Hierarchy& hierarchy, const Camera& camera, uint32_t width, uint32_t height,
                      const glm::dvec3& origin, double nearW, const SelectionLimits& limits) {
  const OctreeMetadata& meta = hierarchy.metadata();
  const glm::dmat4 viewProj = viewProjection(camera, origin, double(width) / double(height));
  auto grown = [&](const NodeKey& key) {
    Bounds cube = meta.nodeCube(key);
    glm::dvec3 margin(kCubeMargin * (cube.max.x - cube.min.x));
    margin = glm::max(margin, 2.0 * meta.scale);
    cube.min -= margin;
    cube.max += margin;
    return cube;
  };
  Selection s;
  std::priority_queue<Candidate> queue;
  const NodeKey root = hierarchy.node(0).info.key;
  if (boxMayBeVisible(grown(root), viewProj, origin, nearW))
    queue.push({std::numeric_limits<double>::infinity(), root, 0});
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
      if (!boxMayBeVisible(grown(key), viewProj, origin, nearW)) continue;
      const double size = projectedRadiusPx(meta.nodeCube(key), camera, height);
      if (size < limits.minNodePx) continue;
      queue.push({size, key, child});
    }
  }
  return s;
}

} // namespace pointrast::lod

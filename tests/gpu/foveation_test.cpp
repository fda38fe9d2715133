// Foveated LOD (render/lod/foveation.h, selection.h) on a hand-built octree of a flat field seen from above:
// the factor grows linearly from 1 at the fovea's edge to the periphery's at the corners; with foveation the
// selection keeps every node around the image's centre and drops nodes in the periphery, and is a subset of
// the selection without it.
#include <algorithm>
#include <cmath>
#include <set>

#include <gtest/gtest.h>

#include "gpu_fixture.h"
#include "lod_octree.h"
#include "render/lod/hierarchy.h"
#include "render/lod/selection.h"

namespace pointrast::test {

namespace {

// Every node of the source, children listed.
lod::Hierarchy fullHierarchy(MemoryOctree& tree) {
  lod::Hierarchy h(tree.meta, tree.root());
  for (uint32_t id = 0; id < h.size(); ++id)
    h.setChildren(id, tree.children(h.node(id).info));
  return h;
}

// A 200 m x 200 m field of points on a 0.5 m grid, z = 0.
PointCloud field() {
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  for (int y = 0; y < 400; ++y)
    for (int x = 0; x < 400; ++x) {
      points.push_back({x * 0.5, y * 0.5, 0.0});
      colors.push_back(0xFF808080u);
    }
  return cloudFromPoints(points, colors, 1e-3);
}

} // namespace

TEST(Foveation, FactorGrowsLinearlyFromTheFoveaToTheCorners) {
  lod::Foveation f{true, 0.3, 3.0};
  EXPECT_EQ(lod::foveationFactor(f, 0.0), 1.0);
  EXPECT_EQ(lod::foveationFactor(f, 0.3), 1.0);
  EXPECT_NEAR(lod::foveationFactor(f, 0.65), 2.0, 1e-12);
  EXPECT_NEAR(lod::foveationFactor(f, 1.0), 3.0, 1e-12);
  EXPECT_NEAR(lod::foveationFactor(f, 1.7), 3.0, 1e-12) << "beyond the corners: the periphery's";
  f.enabled = false;
  EXPECT_EQ(lod::foveationFactor(f, 1.0), 1.0);
}

TEST(Foveation, FewerNodesInThePeripheryTheCentreUnchanged) {
  MemoryOctree tree;
  buildOctree(tree, field(), 100, 16);
  const lod::Hierarchy h = fullHierarchy(tree);
  ASSERT_GT(h.size(), 200u);
  const uint32_t width = 400, height = 300;
  Camera camera;
  camera.eye = {100, 100, 60};
  camera.target = {100, 100, 0};
  camera.up = {0, 1, 0};
  const glm::dvec3 origin{100, 100, 0};
  const double nearW = 0.01;
  lod::SelectionLimits limits;
  limits.minNodePx = 10;
  const lod::Selection plain = lod::selectNodes(h, camera, width, height, origin, nearW, limits);
  limits.foveation = {true, 0.3, 3.0};
  const lod::Selection foveated = lod::selectNodes(h, camera, width, height, origin, nearW, limits);
  const std::set<uint32_t> all(plain.nodes.begin(), plain.nodes.end());
  const std::set<uint32_t> kept(foveated.nodes.begin(), foveated.nodes.end());
  EXPECT_TRUE(std::includes(all.begin(), all.end(), kept.begin(), kept.end())) << "a subset";
  // Where each node's centre lands, in half-diagonals from the image's centre.
  const glm::dmat4 viewProj = viewProjection(camera, origin, double(width) / height);
  const double halfDiagonal = 0.5 * std::hypot(double(width), double(height));
  auto distance = [&](uint32_t id) {
    const glm::dvec4 c =
        viewProj * glm::dvec4(tree.meta.nodeCube(h.node(id).info.key).center() - origin, 1.0);
    const glm::dvec2 px{(c.x / c.w + 1) * 0.5 * width, (1 - c.y / c.w) * 0.5 * height};
    return glm::length(px - glm::dvec2(width, height) * 0.5) / halfDiagonal;
  };
  size_t centre = 0, peripheryAll = 0, peripheryKept = 0;
  for (uint32_t id : all) {
    const double d = distance(id);
    if (d <= 0.3) {
      ++centre;
      EXPECT_TRUE(kept.count(id)) << h.describe(id) << " in the fovea was dropped";
    }
    if (d >= 0.7) {
      ++peripheryAll;
      peripheryKept += kept.count(id);
    }
  }
  EXPECT_GT(centre, 10u);
  EXPECT_GT(peripheryAll, 10u);
  EXPECT_LT(peripheryKept * 3, peripheryAll * 2) << "at least a third fewer nodes in the periphery";
  EXPECT_LT(foveated.points, plain.points);
  // A fovea as large as the image changes nothing.
  limits.foveation = {true, 1.0, 3.0};
  EXPECT_EQ(lod::selectNodes(h, camera, width, height, origin, nearW, limits).nodes, plain.nodes);
}

} // namespace pointrast::test

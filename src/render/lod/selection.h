// Which octree nodes a frame draws, chosen on the CPU as Potree does (Schuetz, "Potree: Rendering Large
// Point Clouds in Web Browsers", 2016; Potree 2's updateVisibility): nodes are taken from a priority queue by
// projected size, largest first, starting at the root; a taken node puts its children in the queue, so a
// node is never taken before its parent. A node outside the view frustum is skipped with its subtree, as is
// one whose projected size is under minNodePx (LOD culling); the traversal stops at the first node that
// would take the selection past a budget.
//
// Projected size is Potree's: the radius in pixels of the node cube's bounding sphere seen at the distance
// of its centre, r H / (2 d tan(fov / 2)); a camera inside the sphere makes it infinite. The root is never
// LOD-culled (a cloud too far away still shows its coarsest level), and nodes of equal size are taken in
// node-key order, so the selection depends on nothing but the hierarchy and the camera.
#pragma once

#include <cstdint>
#include <vector>

#include "render/camera.h"
#include "render/lod/hierarchy.h"

namespace pointrast::lod {

struct SelectionLimits {
  double minNodePx = 100;   // LOD culling: smallest projected radius taken, in pixels (0: none)
  uint64_t pointBudget = 0; // most points selected (0: no limit)
  uint64_t pageBudget = 0;  // most node-cache pages the selection may occupy (0: no limit)
};

struct Selection {
  std::vector<uint32_t> nodes; // in the order taken: largest projected size first, parents before children
  uint64_t points = 0;
  uint64_t pages = 0;
  // Taken nodes whose children are not known yet: the selection may grow once their hierarchy is read.
  std::vector<uint32_t> unexpanded;
  bool limited = false; // a budget stopped the traversal
};

// Pages of the node cache a node of `points` points takes (shared.h, kLodPagePoints).
uint64_t pagesOf(uint64_t points);

// Potree's projected size of a cube (above); +infinity with the eye inside its bounding sphere.
double projectedRadiusPx(const Bounds& cube, const Camera& camera, uint32_t height);

// Whether a box (world coordinates) may hold a point inside the view: false only if all its corners are
// beyond one plane of the frustum (left, right, top, bottom, or not beyond the near plane).
bool boxMayBeVisible(const Bounds& box, const glm::dmat4& viewProj, const glm::dvec3& origin, double nearW);

// The selection for a camera and an image of width x height pixels. `origin` and `nearW` are the frame's
// (render/camera.h: viewProjection, defaultNear).
Selection selectNodes(const Hierarchy& hierarchy, const Camera& camera, uint32_t width, uint32_t height,
                      const glm::dvec3& origin, double nearW, const SelectionLimits& limits);

} // namespace pointrast::lod

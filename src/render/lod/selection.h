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
//
// Stereo frames select once for both eyes: a node is taken when either eye's frustum may hold it, with the
// larger of its projected sizes in the two eyes (the union of both eyes' selections, so both halves of the
// frame draw the same nodes). Foveated LOD (the 2022 paper, sections 3.7 and 4.3) divides a node's projected
// size by a factor that grows from 1 in the fovea to Foveation::periphery at the image's corners, so the
// periphery needs larger nodes (the paper: 100 px in the centre up to 300 px at the edge).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "render/camera.h"
#include "render/lod/foveation.h"
#include "render/lod/hierarchy.h"

namespace pointrast::lod {

struct SelectionLimits {
  double minNodePx = 100;   // LOD culling: smallest projected radius taken, in pixels (0: none)
  Foveation foveation;
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

// The size a node's cube (world coordinates) counts with for one camera: its projected size divided by the
// foveation factor at its distance from the image's centre (the projected size itself without foveation).
// viewProj is the camera's relative to `origin`.
double foveatedSizePx(const Bounds& cube, const Camera& camera, const glm::dmat4& viewProj,
                      const glm::dvec3& origin, uint32_t width, uint32_t height, const Foveation& foveation);

// The selection for one camera, or the two eyes of a stereo frame, and an image of width x height pixels
// (each eye's). `origin` and `nearW` are the frame's (render/camera.h: viewProjection, defaultNear).
Selection selectNodes(const Hierarchy& hierarchy, std::span<const Camera> cameras, uint32_t width,
                      uint32_t height, const glm::dvec3& origin, double nearW, const SelectionLimits& limits);
inline Selection selectNodes(const Hierarchy& hierarchy, const Camera& camera, uint32_t width, uint32_t height,
                             const glm::dvec3& origin, double nearW, const SelectionLimits& limits) {
  return selectNodes(hierarchy, std::span<const Camera>(&camera, 1), width, height, origin, nearW, limits);
}

// Share `index` of `shares` of a selection (a rank's part of a distributed frame, docs/mpi.md): its nodes
// with points in key order, cut into `shares` contiguous runs balanced by points (run k starts at the first
// node whose preceding points reach k / shares of the total). Every rank computes every run alike, and the
// runs tile the selection. The result lists its nodes in key order; unexpanded is left empty.
Selection shareOf(const Selection& selection, const Hierarchy& hierarchy, uint32_t index, uint32_t shares);

} // namespace pointrast::lod

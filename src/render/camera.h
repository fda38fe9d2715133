// The camera contract of docs/design.md: right-handed, OpenGL-style view; eye/target/up in the input's own
// coordinates; vertical field of view in degrees; clip w = linear view depth; points with w <= near are
// dropped. Matrices handed to the GPU are built in double relative to a scene origin and rounded once.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cloud/cloud.h"

namespace pointrast::lod {
class NodeSource;
}

namespace pointrast {

struct Camera {
  glm::dvec3 eye{0, 0, 1};
  glm::dvec3 target{0, 0, 0};
  glm::dvec3 up{0, 0, 1};
  double fovY = 60.0; // degrees
  double nearW = 0.0; // 0: automatic, defaultNear(bounds)
  // Horizontal shift of the image in normalized device coordinates (clip x += shiftX * clip w): an
  // off-axis frustum, as a stereo eye's (render/stereo.h). 0 for every mono camera.
  double shiftX = 0.0;
};

// The overview used when no camera is given: looking at the bounds face on to their longer horizontal
// side (from the south when x is the longer, else from the west), 35 degrees above the horizon, z up,
// framed as framingCamera does. Empty bounds (a cloud without points) get the same view of the origin.
// fovY must be in (0, 180). With `points` (a sample of the cloud, framingSample()) the points are framed
// rather than the box's corners: a cloud fills the window however little of its box it occupies.
Camera overviewCamera(const Bounds& bounds, double aspect, double fovY = 60.0,
                      std::span<const glm::dvec3> points = {});

// Points that stand for a cloud's shape when framing it: every n-th point, at most maxPoints.
std::vector<glm::dvec3> framingSample(const PointCloud& cloud, size_t maxPoints = size_t(1) << 16);
// An octree's root node (its coarsest subsample of the whole cloud), at most maxPoints of it; empty when
// the root holds no points or cannot be read (framing then falls back to the bounds).
std::vector<glm::dvec3> framingSample(lod::NodeSource& source, size_t maxPoints = size_t(1) << 16);

// kMaxCoordinate and checkCoordinateRange (cloud/cloud.h) bound what is rendered.

// Framing from any direction: looking along -back (unit vector from the target towards the eye) with the
// given up (not parallel to back), at the smallest distance that keeps all eight corners of the bounding
// box (or every one of `points`, when given) in the image, plus 5 %, with the target moved in the image plane so that the box's projection is
// centered in the image (the target is the center of the bounds only when the projection is symmetric);
// never closer than the coordinates' magnitude lets doubles tell the eye from the target. The overview,
// views from the axes and "frame all" in the viewer.
Camera framingCamera(const Bounds& bounds, double aspect, double fovY, const glm::dvec3& back,
                     const glm::dvec3& up, std::span<const glm::dvec3> points = {});

// 1e-5 of the bounds' diagonal (at least 1e-9): far below any visible point, so it only drops points
// at or behind the eye.
double defaultNear(const Bounds& bounds);

// What can be wrong with a camera; front ends map each to their own option names.
enum class CameraProblem {
  NotFinite,   // eye, target or up not finite
  EyeIsTarget, // no view direction
  UpIsZero,
  UpAlongView, // up parallel to the view direction
  FieldOfView, // fovY outside (0, 180)
  Near,        // nearW negative or not finite
};
// The first problem of the camera, if any.
std::optional<CameraProblem> findCameraProblem(const Camera& camera);
// One neutral sentence for a problem ("the camera's eye and target are the same point").
const char* describeCameraProblem(CameraProblem problem);
// Throws InputError with describeCameraProblem's sentence when the camera has a problem.
void validateCamera(const Camera& camera);

// Clip-from-world matrix with world coordinates taken relative to `origin`:
// clip = P * V * (p - origin). Only rows x, y and w matter (no far plane: depth is linear).
glm::dmat4 viewProjection(const Camera& camera, const glm::dvec3& origin, double aspect);

std::string describeCamera(const Camera& camera);

} // namespace pointrast

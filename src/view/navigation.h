// Camera navigation of the interactive viewers, after Potree and CloudCompare: orbit around a pivot,
// pan, zoom towards the cursor, fly, views along the axes, frame the whole cloud. Pure double-precision
// math on the Camera of render/camera.h (no GPU, no window), shared by every front end.
//
// Conventions: pixels are (x right, y down) in the viewport, continuous (the center of pixel (i, j) is
// (i + 0.5, j + 0.5)), as in docs/design.md's pixel contract. The scene's vertical axis is the camera's `up`
// (z by default). Drags are absolute: the camera during a drag is a function of the start camera and the
// cursor's total offset, so the result never depends on how many motion events the window system sent.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/glm.hpp>

#include "cloud/cloud.h"
#include "render/camera.h"

namespace pointrast::view {

struct Viewport {
  uint32_t width = 1, height = 1;
  double aspect() const { return double(width) / double(height); }
  bool operator==(const Viewport&) const = default;
};

// Orbit speed: a drag over the viewport's full height turns the camera by 180 degrees.
constexpr double kOrbitRadiansPerHeight = 3.14159265358979323846;
// The view direction's elevation stays within +-89.5 degrees: `up` never becomes parallel to it.
constexpr double kMaxElevationDegrees = 89.5;
// One wheel step scales the distances to the point under the cursor by this factor (zoom in).
constexpr double kZoomPerStep = 0.8;
// Fly speed in bounds diagonals per second, and the factor while Shift is held.
constexpr double kFlyDiagonalsPerSecond = 0.2;
constexpr double kFlyFastFactor = 5.0;

// Direction through a viewport position, scaled so that its component along the view direction is 1:
// the point at linear depth w (clip w, the depth the framebuffer stores) is eye + ray * w.
glm::dvec3 pixelRay(const Camera& camera, Viewport viewport, glm::dvec2 position);
// The point at linear depth `depth` under a viewport position.
glm::dvec3 unproject(const Camera& camera, Viewport viewport, glm::dvec2 position, double depth);
// Viewport position and linear depth of a world point (depth <= 0: behind the eye).
glm::dvec3 project(const Camera& camera, Viewport viewport, const glm::dvec3& point);

// The camera turned around `pivot`: first by `pitch` radians about the camera's right axis (positive
// raises the view direction), its elevation above the plane normal to `vertical` (unit) clamped to
// kMaxElevationDegrees, then by `yaw` radians about `vertical` (counterclockwise seen from above). Eye and
// target turn together, distances to the pivot are kept, and the result's up is `vertical` (a view
// straight down, whose up is another axis, turns into one 0.5 degrees off).
Camera orbit(const Camera& start, const glm::dvec3& pivot, const glm::dvec3& vertical, double yaw,
             double pitch);
// The camera moved parallel to the image plane so that a point at linear depth `depth` follows the
// cursor's offset `delta` (pixels).
Camera pan(const Camera& start, Viewport viewport, glm::dvec2 delta, double depth);
// The camera scaled towards `point` by `factor` (< 1 zooms in): eye and target move along their lines to
// the point, so the point stays under the same pixel and the view direction is kept.
Camera zoomTowards(const Camera& start, const glm::dvec3& point, double factor);

// Axis views: CloudCompare's keys 8 top, 2 bottom, 5 front (looking north, +y), 0 back, 4 left side
// (looking east, +x), 6 right side. Iso looks from the south-west, 35 degrees above the horizon.
enum class StandardView { Top, Bottom, Front, Back, Left, Right, Iso };
const char* standardViewName(StandardView view);

enum class DragMode { None, Orbit, Pan };

// What the fly keys hold: each axis -1, 0 or +1 (forward/back W/S, right/left D/A, up/down E/Q).
struct FlyInput {
  int forward = 0, right = 0, up = 0;
  bool fast = false;
  bool any() const { return forward != 0 || right != 0 || up != 0; }
};

class Navigation {
public:
  // The cloud's bounds set the speeds and what "frame all" frames. The pivot starts at the target; the
  // camera's up is the scene's vertical axis from then on.
  Navigation(const Bounds& bounds, const Camera& camera);

  const Camera& camera() const { return camera_; }
  const glm::dvec3& pivot() const { return pivot_; }
  const Bounds& bounds() const { return bounds_; }
  // Replaces the camera (a keyframe, --eye); the pivot moves to its target.
  void setCamera(const Camera& camera);
  // The orbit center, e.g. a picked point; the view does not move.
  void setPivot(const glm::dvec3& pivot) { pivot_ = pivot; }

  void beginDrag(DragMode mode, glm::dvec2 cursor);
  // Sets the camera for the cursor's offset since beginDrag; returns whether it changed.
  bool drag(glm::dvec2 cursor, Viewport viewport);
  void endDrag() { mode_ = DragMode::None; }
  DragMode dragMode() const { return mode_; }

  // `steps` wheel steps (positive: in) towards the point under the cursor: at `depth` when the front end
  // read one from the framebuffer, else on the plane through the pivot facing the camera.
  void zoom(glm::dvec2 cursor, double steps, Viewport viewport, std::optional<double> depth = std::nullopt);
  // Moves eye, target and pivot for `seconds` of flight; returns whether anything moved.
  bool fly(const FlyInput& input, double seconds);
  // Views along the axes and "frame all" look at the bounds' center from far enough to see all of it;
  // the pivot moves to the center. frameAll keeps the view direction.
  void viewFrom(StandardView view, Viewport viewport);
  void frameAll(Viewport viewport);

private:
  // Linear depth of the pivot, or of the target when the pivot is behind the eye.
  double pivotDepth() const;
  Bounds bounds_;
  glm::dvec3 vertical_;
  Camera camera_;
  glm::dvec3 pivot_;
  DragMode mode_ = DragMode::None;
  Camera dragCamera_;
  glm::dvec3 dragPivot_{0};
  glm::dvec2 dragStart_{0};
};

} // namespace pointrast::view

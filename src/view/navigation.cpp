#include "view/navigation.h"

#include <algorithm>
#include <cmath>

namespace pointrast::view {

namespace {

struct Basis {
  glm::dvec3 forward, right, up; // up: the image's up, orthogonal to forward (glm::lookAt's u)
};

// The same orthonormal basis glm::lookAtRH builds from eye, target and up (render/camera.cpp).
Basis basis(const Camera& camera) {
  Basis b;
  b.forward = glm::normalize(camera.target - camera.eye);
  b.right = glm::normalize(glm::cross(b.forward, camera.up));
  b.up = glm::cross(b.right, b.forward);
  return b;
}

// Rodrigues' rotation of v about the unit axis by angle radians.
glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& axis, double angle) {
  double c = std::cos(angle), s = std::sin(angle);
  return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1 - c);
}

double tanHalfFov(const Camera& camera) {
  return std::tan(glm::radians(camera.fovY) / 2);
}

} // namespace

glm::dvec3 pixelRay(const Camera& camera, Viewport viewport, glm::dvec2 position) {
  Basis b = basis(camera);
  double tanY = tanHalfFov(camera), tanX = tanY * viewport.aspect();
  double ndcX = 2 * position.x / viewport.width - 1;
  double ndcY = 1 - 2 * position.y / viewport.height;
  return b.forward + b.right * (ndcX * tanX) + b.up * (ndcY * tanY);
}

glm::dvec3 unproject(const Camera& camera, Viewport viewport, glm::dvec2 position, double depth) {
  return camera.eye + pixelRay(camera, viewport, position) * depth;
}

glm::dvec3 project(const Camera& camera, Viewport viewport, const glm::dvec3& point) {
  Basis b = basis(camera);
  glm::dvec3 v = point - camera.eye;
  double depth = glm::dot(v, b.forward);
  double tanY = tanHalfFov(camera), tanX = tanY * viewport.aspect();
  double ndcX = glm::dot(v, b.right) / (depth * tanX);
  double ndcY = glm::dot(v, b.up) / (depth * tanY);
  return {(ndcX + 1) / 2 * viewport.width, (1 - ndcY) / 2 * viewport.height, depth};
}

Camera orbit(const Camera& start, const glm::dvec3& pivot, const glm::dvec3& vertical, double yaw,
             double pitch) {
  Basis b = basis(start);
  double limit = glm::radians(kMaxElevationDegrees);
  double elevation = std::asin(std::clamp(glm::dot(b.forward, vertical), -1.0, 1.0));
  double turn = std::clamp(elevation + pitch, -limit, limit) - elevation;
  Camera camera = start;
  auto transform = [&](const glm::dvec3& p) {
    glm::dvec3 v = rotate(p - pivot, b.right, turn);
    return pivot + rotate(v, vertical, yaw);
  };
  camera.eye = transform(start.eye);
  camera.target = transform(start.target);
  camera.up = vertical;
  return camera;
}

Camera pan(const Camera& start, Viewport viewport, glm::dvec2 delta, double depth) {
  Basis b = basis(start);
  // One pixel at linear depth d spans 2 d tan(fov/2) / height world units, horizontally and vertically.
  double unitsPerPixel = 2 * depth * tanHalfFov(start) / viewport.height;
  glm::dvec3 shift = (-delta.x * b.right + delta.y * b.up) * unitsPerPixel;
  Camera camera = start;
  camera.eye += shift;
  camera.target += shift;
  return camera;
}

Camera zoomTowards(const Camera& start, const glm::dvec3& point, double factor) {
  Camera camera = start;
  camera.eye = point + (start.eye - point) * factor;
  camera.target = point + (start.target - point) * factor;
  return camera;
}

const char* standardViewName(StandardView view) {
  switch (view) {
  case StandardView::Top:
    return "top";
  case StandardView::Bottom:
    return "bottom";
  case StandardView::Front:
    return "front";
  case StandardView::Back:
    return "back";
  case StandardView::Left:
    return "left";
  case StandardView::Right:
    return "right";
  case StandardView::Iso:
    return "iso";
  }
  return "?";
}

Navigation::Navigation(const Bounds& bounds, const Camera& camera)
    : bounds_(bounds), vertical_(glm::normalize(camera.up)), camera_(camera), pivot_(camera.target) {}

void Navigation::setCamera(const Camera& camera) {
  camera_ = camera;
  pivot_ = camera.target;
  mode_ = DragMode::None;
}

void Navigation::beginDrag(DragMode mode, glm::dvec2 cursor) {
  mode_ = mode;
  dragCamera_ = camera_;
  dragPivot_ = pivot_;
  dragStart_ = cursor;
}

bool Navigation::drag(glm::dvec2 cursor, Viewport viewport) {
  glm::dvec2 delta = cursor - dragStart_;
  Camera before = camera_;
  if (mode_ == DragMode::Orbit) {
    // The scene follows the cursor: dragging right turns the camera clockwise (seen from above), dragging
    // down raises the eye.
    double radiansPerPixel = kOrbitRadiansPerHeight / viewport.height;
    camera_ =
        orbit(dragCamera_, dragPivot_, vertical_, -delta.x * radiansPerPixel, -delta.y * radiansPerPixel);
  } else if (mode_ == DragMode::Pan) {
    Navigation start = *this;
    start.camera_ = dragCamera_;
    start.pivot_ = dragPivot_;
    camera_ = pan(dragCamera_, viewport, delta, start.pivotDepth());
    // The pivot travels with the view, so that orbiting after a pan turns around what is on screen.
    pivot_ = dragPivot_ + (camera_.eye - dragCamera_.eye);
  }
  return camera_.eye != before.eye || camera_.target != before.target;
}

double Navigation::pivotDepth() const {
  Basis b = basis(camera_);
  double depth = glm::dot(pivot_ - camera_.eye, b.forward);
  if (depth > 0) return depth;
  return glm::dot(camera_.target - camera_.eye, b.forward);
}

void Navigation::zoom(glm::dvec2 cursor, double steps, Viewport viewport, std::optional<double> depth) {
  double d = depth && *depth > 0 ? *depth : pivotDepth();
  glm::dvec3 point = unproject(camera_, viewport, cursor, d);
  camera_ = zoomTowards(camera_, point, std::pow(kZoomPerStep, steps));
}

bool Navigation::fly(const FlyInput& input, double seconds) {
  if (!input.any() || seconds <= 0) return false;
  Basis b = basis(camera_);
  double diagonal = bounds_.empty() ? 1.0 : std::max(bounds_.diagonal(), 1e-9);
  double distance = diagonal * kFlyDiagonalsPerSecond * (input.fast ? kFlyFastFactor : 1.0) * seconds;
  glm::dvec3 move =
      (b.forward * double(input.forward) + b.right * double(input.right) + vertical_ * double(input.up)) *
      distance;
  camera_.eye += move;
  camera_.target += move;
  pivot_ += move;
  return true;
}

void Navigation::viewFrom(StandardView view, Viewport viewport) {
  // back: from the target towards the eye; up: the image's up. The axis views assume z is vertical.
  glm::dvec3 back, up = vertical_;
  switch (view) {
  case StandardView::Top:
    back = {0, 0, 1};
    up = {0, 1, 0};
    break;
  case StandardView::Bottom:
    back = {0, 0, -1};
    up = {0, 1, 0};
    break;
  case StandardView::Front:
    back = {0, -1, 0};
    break;
  case StandardView::Back:
    back = {0, 1, 0};
    break;
  case StandardView::Left:
    back = {-1, 0, 0};
    break;
  case StandardView::Right:
    back = {1, 0, 0};
    break;
  case StandardView::Iso:
    back = glm::normalize(glm::dvec3(-1, -1, 1));
    break;
  }
  Camera framed = framingCamera(bounds_, viewport.aspect(), camera_.fovY, back, up);
  framed.nearW = camera_.nearW;
  setCamera(framed);
}

void Navigation::frameAll(Viewport viewport) {
  Basis b = basis(camera_);
  // Straight down (after the top view) the image's up stays what it was; otherwise the vertical.
  glm::dvec3 up = std::abs(glm::dot(b.forward, vertical_)) > 0.9999 ? b.up : vertical_;
  Camera framed = framingCamera(bounds_, viewport.aspect(), camera_.fovY, -b.forward, up);
  framed.nearW = camera_.nearW;
  setCamera(framed);
}

} // namespace pointrast::view

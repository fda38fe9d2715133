#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/gtc/matrix_transform.hpp>

#include "base/error.h"

namespace pointrast {

double defaultNear(const Bounds& bounds) {
  return std::max(1e-9, 1e-5 * bounds.diagonal());
}

Camera overviewCamera(const Bounds& bounds, double aspect, double fovY) {
  return framingCamera(bounds, aspect, fovY, glm::normalize(glm::dvec3(-1, -1, 1)), {0, 0, 1});
}

Camera framingCamera(const Bounds& bounds, double aspect, double fovY, const glm::dvec3& back,
                     const glm::dvec3& up) {
  Camera camera;
  camera.fovY = fovY;
  camera.up = up;
  if (bounds.empty()) { // a cloud without points: the same view of the origin
    camera.target = glm::dvec3(0);
    camera.eye = back;
    return camera;
  }
  glm::dvec3 center = bounds.center();
  glm::dvec3 right = glm::normalize(glm::cross(-back, camera.up));
  glm::dvec3 upv = glm::cross(right, -back);
  double tanY = std::tan(glm::radians(fovY) / 2), tanX = tanY * aspect;
  // A corner at offset v is inside when |v.right| <= tanX * (D - v.back) and the same for up; solve for
  // the eye distance D along `back`.
  double distance = 0, deepest = 0;
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 corner{i & 1 ? bounds.max.x : bounds.min.x, i & 2 ? bounds.max.y : bounds.min.y,
                      i & 4 ? bounds.max.z : bounds.min.z};
    glm::dvec3 v = corner - center;
    double along = glm::dot(v, back);
    deepest = std::max(deepest, along);
    distance = std::max(
        {distance, std::abs(glm::dot(v, right)) / tanX + along, std::abs(glm::dot(v, upv)) / tanY + along});
  }
  // Keep every corner in front of the eye even for degenerate (flat or single-point) bounds, and the eye
  // 1e-7 of the coordinates' magnitude (some 10^8 steps of double precision) away from the center however
  // far that lies from the origin.
  const double magnitude = std::max(glm::length(bounds.min), glm::length(bounds.max));
  distance = std::max(distance * 1.05, deepest + 1e-3 * bounds.diagonal() + std::max(1e-6, 1e-7 * magnitude));
  camera.target = center;
  camera.eye = center + back * distance;
  return camera;
}

std::optional<CameraProblem> findCameraProblem(const Camera& camera) {
  auto finite = [](const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!finite(camera.eye) || !finite(camera.target) || !finite(camera.up) || !std::isfinite(camera.shiftX))
    return CameraProblem::NotFinite;
  if (!(camera.fovY > 0 && camera.fovY < 180)) return CameraProblem::FieldOfView;
  if (!(camera.nearW >= 0) || !std::isfinite(camera.nearW)) return CameraProblem::Near;
  glm::dvec3 view = camera.target - camera.eye;
  if (!(glm::length(view) > 0)) return CameraProblem::EyeIsTarget;
  if (!(glm::length(camera.up) > 0)) return CameraProblem::UpIsZero;
  if (!(glm::length(glm::cross(glm::normalize(view), glm::normalize(camera.up))) >= 1e-9))
    return CameraProblem::UpAlongView;
  return std::nullopt;
}

const char* describeCameraProblem(CameraProblem problem) {
  switch (problem) {
  case CameraProblem::NotFinite:
    return "the camera's eye, target and up must be finite numbers";
  case CameraProblem::EyeIsTarget:
    return "the camera's eye and target are the same point";
  case CameraProblem::UpIsZero:
    return "the camera's up direction is zero";
  case CameraProblem::UpAlongView:
    return "the camera's up direction is parallel to its view direction";
  case CameraProblem::FieldOfView:
    return "the field of view must be between 0 and 180 degrees";
  case CameraProblem::Near:
    return "the near distance must be a number >= 0";
  }
  return "the camera is not usable";
}

void validateCamera(const Camera& camera) {
  if (auto problem = findCameraProblem(camera)) throw InputError(describeCameraProblem(*problem));
}

glm::dmat4 viewProjection(const Camera& camera, const glm::dvec3& origin, double aspect) {
  glm::dmat4 view = glm::lookAtRH(camera.eye - origin, camera.target - origin, camera.up);
  // glm::perspectiveRH_NO puts the linear view depth (-z_view) in clip w; its z row is unused here.
  double nearW = camera.nearW > 0 ? camera.nearW : 1e-6;
  glm::dmat4 proj = glm::perspectiveRH_NO(glm::radians(camera.fovY), aspect, nearW, nearW * 1e9);
  // The off-axis shift adds shiftX times row w to row x (w = -z_view; a zero shift leaves proj as is).
  if (camera.shiftX != 0.0) proj[2][0] -= camera.shiftX;
  return proj * view;
}

std::string describeCamera(const Camera& c) {
  char text[256];
  std::snprintf(text, sizeof text,
                "--eye %.17g,%.17g,%.17g --target %.17g,%.17g,%.17g --up %g,%g,%g --fov %g", c.eye.x, c.eye.y,
                c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z, c.fovY);
  return text;
}

} // namespace pointrast

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
  if (bounds.empty()) return camera;
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
  // Keep every corner in front of the eye even for degenerate (flat or single-point) bounds.
  distance = std::max(distance * 1.05, deepest + 1e-3 * bounds.diagonal() + 1e-6);
  camera.target = center;
  camera.eye = center + back * distance;
  return camera;
}

void validateCamera(const Camera& camera) {
  auto finite = [](const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!finite(camera.eye) || !finite(camera.target) || !finite(camera.up))
    throw InputError("camera: eye, target and up must be finite numbers");
  glm::dvec3 view = camera.target - camera.eye;
  if (glm::length(view) <= 0) throw InputError("camera: --eye and --target must differ");
  if (glm::length(camera.up) <= 0) throw InputError("camera: --up must not be zero");
  if (glm::length(glm::cross(glm::normalize(view), glm::normalize(camera.up))) < 1e-9)
    throw InputError("camera: --up is parallel to the view direction; give another --up");
  if (!(camera.fovY > 0 && camera.fovY < 180))
    throw InputError("camera: --fov must be between 0 and 180 degrees");
  if (!(camera.nearW >= 0) || !std::isfinite(camera.nearW)) throw InputError("camera: --near must be >= 0");
}

glm::dmat4 viewProjection(const Camera& camera, const glm::dvec3& origin, double aspect) {
  glm::dmat4 view = glm::lookAtRH(camera.eye - origin, camera.target - origin, camera.up);
  // glm::perspectiveRH_NO puts the linear view depth (-z_view) in clip w; its z row is unused here.
  double nearW = camera.nearW > 0 ? camera.nearW : 1e-6;
  glm::dmat4 proj = glm::perspectiveRH_NO(glm::radians(camera.fovY), aspect, nearW, nearW * 1e9);
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

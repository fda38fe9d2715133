#include "render/stereo.h"

#include <cmath>
#include <limits>
#include <string>

#include "base/error.h"

namespace pointrast {

namespace {

// The 1/30 rule: the nearest comfortable depth at this separation lies at about the convergence distance.
constexpr double kSeparationPerDistance = 1.0 / 30.0;

} // namespace

double convergenceDistance(const Camera& camera, const StereoSettings& settings) {
  return settings.convergence > 0 ? settings.convergence : glm::length(camera.target - camera.eye);
}

double eyeSeparation(const Camera& camera, const StereoSettings& settings) {
  if (settings.separation > 0) return settings.separation;
  const double distance = convergenceDistance(camera, settings);
  // Parallel eyes have no convergence plane to scale by: the target's distance stands in.
  return kSeparationPerDistance * (std::isinf(distance) ? glm::length(camera.target - camera.eye) : distance);
}

Camera eyeCamera(const Camera& camera, const StereoSettings& settings, Eye eye, double aspect) {
  const double side = eye == Eye::Left ? -1.0 : 1.0;
  const double half = 0.5 * eyeSeparation(camera, settings);
  const glm::dvec3 right = glm::normalize(glm::cross(camera.target - camera.eye, camera.up));
  Camera c = camera;
  c.eye += side * half * right;
  c.target += side * half * right; // parallel view directions
  const double distance = convergenceDistance(camera, settings);
  if (!std::isinf(distance)) {
    // A point on the convergence plane straight ahead of the given eye lies -side * half to the side of
    // this eye, at x/w = -side * half / (distance tanX) in its symmetric frustum: shift it back to 0.
    const double tanX = std::tan(glm::radians(camera.fovY) / 2.0) * aspect;
    c.shiftX = side * half / (distance * tanX);
  }
  return c;
}

Eye eyeOfHalf(const StereoSettings& settings, uint32_t half) {
  const bool left = (half == 0) != settings.crossed;
  return left ? Eye::Left : Eye::Right;
}

void validateStereo(const StereoSettings& settings) {
  if (!(settings.separation >= 0) || !std::isfinite(settings.separation))
    throw InputError("the eye separation must be a finite number >= 0 (0: the convergence distance / 30)");
  if (!(settings.convergence >= 0))
    throw InputError("the convergence distance must be a number > 0, or inf for parallel eyes");
}

double parseConvergence(std::string_view text) {
  if (text == "inf" || text == "infinity") return std::numeric_limits<double>::infinity();
  const std::string s(text);
  size_t used = 0;
  double value = 0;
  try {
    value = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != s.size() || !(value > 0) || std::isinf(value))
    throw InputError("--convergence takes a distance > 0 in scene units, or inf for parallel eyes; got '" +
                     s + "'");
  return value;
}

} // namespace pointrast

#include "bench/views.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "base/error.h"

namespace pointrast::bench {

namespace {
constexpr View kViews[] = {View::Overview, View::Closeup, View::Outside};
constexpr const char* kViewNames[] = {"overview", "closeup", "outside"};
constexpr Orbit kOrbits[] = {Orbit::Short, Orbit::Long};
constexpr const char* kOrbitNames[] = {"short", "long"};
} // namespace

View parseView(std::string_view name) {
  for (View v : kViews)
    if (name == kViewNames[int(v)]) return v;
  throw InputError("unknown view '" + std::string(name) + "'; choose overview, closeup or outside");
}

const char* viewName(View view) {
  return kViewNames[int(view)];
}

std::span<const View> allViews() {
  return kViews;
}

Camera viewCamera(View view, const Bounds& bounds, double aspect, double fovY) {
  if (view == View::Overview || bounds.empty()) return overviewCamera(bounds, aspect, fovY);
  Camera camera;
  camera.fovY = fovY;
  camera.up = {0, 0, 1};
  const glm::dvec3 center = bounds.center();
  // Any positive length works for the target (only the direction matters); keep it of the scene's
  // scale, and at least one unit for single-point or flat bounds.
  const double reach = std::max(bounds.diagonal(), 1.0);
  if (view == View::Closeup) {
    camera.eye = center;
    camera.target = center + glm::dvec3(reach, 0, 0);
  } else {
    // Every point has x >= min.x > eye.x, and the view looks along -x, so each point's linear depth
    // (its distance along the view direction) is at most -margin: behind the eye, dropped by the
    // w <= near test whatever the field of view. The margin keeps float rounding far from the edge.
    const double margin = 0.25 * reach;
    camera.eye = {bounds.min.x - margin, center.y, center.z};
    camera.target = camera.eye - glm::dvec3(reach, 0, 0);
  }
  return camera;
}

Orbit parseOrbit(std::string_view name) {
  for (Orbit o : kOrbits)
    if (name == kOrbitNames[int(o)]) return o;
  throw InputError("unknown orbit '" + std::string(name) + "'; choose short or long");
}

const char* orbitName(Orbit orbit) {
  return kOrbitNames[int(orbit)];
}

std::span<const Orbit> allOrbits() {
  return kOrbits;
}

std::vector<Camera> orbitCameras(Orbit orbit, const Bounds& bounds, double aspect, double fovY,
                                 uint32_t count) {
  const glm::dvec3 center = bounds.center();
  const glm::dvec3 half = 0.5 * (bounds.max - bounds.min);
  const double reach = std::max(bounds.diagonal(), 1e-3);
  // Long: the enclosing sphere of the bounds (radius half the diagonal) fills the narrower field of view, so
  // the eye is outside it (distance = radius / sin(half angle) > radius), hence outside the bounds.
  const double halfY = glm::radians(fovY) / 2;
  const double halfX = std::atan(std::tan(halfY) * aspect);
  const double distance = 0.5 * reach / std::sin(std::min(halfX, halfY));
  const double elevation = glm::radians(20.0);
  std::vector<Camera> cameras(count);
  for (uint32_t k = 0; k < count; ++k) {
    // From the south-west (225 degrees), counter-clockwise.
    const double angle = 1.25 * std::numbers::pi + 2 * std::numbers::pi * double(k) / double(count);
    const glm::dvec2 around(std::cos(angle), std::sin(angle));
    Camera& c = cameras[k];
    c.fovY = fovY;
    c.up = {0, 0, 1};
    c.target = center;
    if (orbit == Orbit::Long) {
      c.eye = center + distance * glm::dvec3(std::cos(elevation) * around, std::sin(elevation));
    } else {
      glm::dvec2 radius = 0.5 * glm::dvec2(half.x, half.y);
      if (radius.x <= 1e-9 * reach || radius.y <= 1e-9 * reach) radius = glm::dvec2(1e-3 * reach);
      c.eye = center + glm::dvec3(radius * around, 0.25 * half.z);
    }
  }
  return cameras;
}

} // namespace pointrast::bench

#include "bench/views.h"

#include <algorithm>
#include <string>

#include "base/error.h"

namespace pointrast::bench {

namespace {
constexpr View kViews[] = {View::Overview, View::Closeup, View::Outside};
constexpr const char* kViewNames[] = {"overview", "closeup", "outside"};
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

} // namespace pointrast::bench

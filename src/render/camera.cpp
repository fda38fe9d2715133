#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/gtc/matrix_transform.hpp>

#include "base/error.h"
#include "cloud/octree.h"

namespace pointrast {

double defaultNear(const Bounds& bounds) {
  return std::max(1e-9, 1e-5 * bounds.diagonal());
}

Camera overviewCamera(const Bounds& bounds, double aspect, double fovY, std::span<const glm::dvec3> points) {
  // Face on to the longer horizontal side: a rectangle seen along its diagonal is a diamond that fills
  // half of the image at best, seen face on a trapezoid that fills most of it.
  const double elevation = glm::radians(35.0);
  const glm::dvec3 size = bounds.size();
  const glm::dvec3 back = size.x >= size.y ? glm::dvec3(0, -std::cos(elevation), std::sin(elevation))
                                           : glm::dvec3(-std::cos(elevation), 0, std::sin(elevation));
  return framingCamera(bounds, aspect, fovY, back, {0, 0, 1}, points);
}

std::vector<glm::dvec3> framingSample(const PointCloud& cloud, size_t maxPoints) {
  std::vector<glm::dvec3> sample;
  const uint64_t n = cloud.size();
  if (n == 0 || maxPoints == 0) return sample;
  const uint64_t step = (n + maxPoints - 1) / maxPoints;
  sample.reserve(size_t(n / step + 1));
  for (uint64_t i = 0; i < n; i += step) sample.push_back(cloud.world(i));
  return sample;
}

std::vector<glm::dvec3> framingSample(lod::NodeSource& source, size_t maxPoints) {
  std::vector<glm::dvec3> sample;
  try {
    const lod::NodeInfo root = source.root();
    if (root.pointCount == 0 || maxPoints == 0) return sample;
    const std::vector<PointRecord> records = source.readNode(root);
    const lod::OctreeMetadata& m = source.metadata();
    const size_t step = (records.size() + maxPoints - 1) / maxPoints;
    for (size_t i = 0; i < records.size(); i += step) {
      const PointRecord& r = records[i];
      sample.push_back(glm::dvec3(r.x, r.y, r.z) * m.scale + m.offset);
    }
  } catch (const InputError&) {
    sample.clear(); // a damaged root is reported where it is drawn; framing uses the bounds
  }
  return sample;
}

Camera framingCamera(const Bounds& bounds, double aspect, double fovY, const glm::dvec3& back,
                     const glm::dvec3& up, std::span<const glm::dvec3> points) {
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
  // The eye sits at target + distance * back, the target at center + shiftRight * right + shiftUp * up: the
  // view direction is fixed, the target slides in the image plane so that the projection is centered
  // rather than the box's center. A point at offset v (from center) is inside horizontally when
  // |v.right - shiftRight| <= tanX * (distance - v.back). A shift exists for all points exactly when
  // max(v.right + tanX v.back) - min(v.right - tanX v.back) <= 2 tanX distance, the same for up: the
  // smallest such distance, then the middle of the shifts it allows.
  std::vector<glm::dvec3> v;
  if (points.empty()) {
    for (int i = 0; i < 8; ++i)
      v.push_back(glm::dvec3{i & 1 ? bounds.max.x : bounds.min.x, i & 2 ? bounds.max.y : bounds.min.y,
                             i & 4 ? bounds.max.z : bounds.min.z} -
                  center);
  } else {
    v.reserve(points.size());
    for (const glm::dvec3& p : points)
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) v.push_back(p - center);
    if (v.empty()) v.push_back(glm::dvec3(0));
  }
  auto fit = [&](const glm::dvec3& axis, double tanA) {
    double hi = -INFINITY, lo = INFINITY;
    for (const glm::dvec3& c : v) {
      hi = std::max(hi, glm::dot(c, axis) + tanA * glm::dot(c, back));
      lo = std::min(lo, glm::dot(c, axis) - tanA * glm::dot(c, back));
    }
    return (hi - lo) / (2 * tanA);
  };
  double distance = std::max(fit(right, tanX), fit(upv, tanY)), deepest = 0;
  for (const glm::dvec3& c : v) deepest = std::max(deepest, glm::dot(c, back));
  // Keep every point in front of the eye even for degenerate (flat or single-point) bounds, and the eye
  // 1e-7 of the coordinates' magnitude (some 10^8 steps of double precision) away from the center however
  // far that lies from the origin.
  const double magnitude = std::max(glm::length(bounds.min), glm::length(bounds.max));
  distance = std::max(distance * 1.05, deepest + 1e-3 * bounds.diagonal() + std::max(1e-6, 1e-7 * magnitude));
  // The shifts: for each axis the interval every point allows at this distance, and in it the shift that
  // centers the projection (the largest and the smallest image coordinate opposite; their sum falls as the
  // shift grows, so bisection finds it).
  auto middleShift = [&](const glm::dvec3& axis, double tanA) {
    double lo = -INFINITY, hi = INFINITY;
    for (const glm::dvec3& c : v) {
      const double reach = tanA * (distance - glm::dot(c, back));
      lo = std::max(lo, glm::dot(c, axis) - reach);
      hi = std::min(hi, glm::dot(c, axis) + reach);
    }
    if (!(lo <= hi)) return 0.0;
    for (int step = 0; step < 60; ++step) {
      const double shift = (lo + hi) / 2;
      double top = -INFINITY, bottom = INFINITY;
      for (const glm::dvec3& c : v) {
        const double image = (glm::dot(c, axis) - shift) / (distance - glm::dot(c, back));
        top = std::max(top, image);
        bottom = std::min(bottom, image);
      }
      (top + bottom > 0 ? lo : hi) = shift;
    }
    return (lo + hi) / 2;
  };
  const glm::dvec3 target = center + middleShift(right, tanX) * right + middleShift(upv, tanY) * upv;
  camera.target = target;
  camera.eye = target + back * distance;
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

#include "oracles/cpu_spheres.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/constants.hpp>

#include "base/parallel.h"
#include "gpu/shared_types.h"

namespace pointrast {

namespace {

constexpr uint32_t kBandRows = 16; // rows per unit of parallel work

struct PixelBox {
  int64_t x0, y0, x1, y1; // inclusive; empty when x1 < x0 or y1 < y0
};

// The camera's basis and the ray of a pixel position: dir = forward + ndc.x * tanX * right
// + ndc.y * tanY * up, so that a point eye + t * dir lies at view depth t (right and up are orthogonal
// to forward).
struct RayCamera {
  glm::dvec3 eye, forward, right, up;
  double tanX, tanY;
  uint32_t width, height;

  glm::dvec3 ray(double px, double py) const {
    double nx = 2.0 * px / width - 1.0, ny = 1.0 - 2.0 * py / height;
    return forward + nx * tanX * right + ny * tanY * up;
  }
  // Pixel position of a point in front of the eye (the inverse of ray()).
  glm::dvec2 project(const glm::dvec3& p) const {
    glm::dvec3 v = p - eye;
    double depth = glm::dot(v, forward);
    double nx = glm::dot(v, right) / (depth * tanX), ny = glm::dot(v, up) / (depth * tanY);
    return {(nx + 1.0) * 0.5 * width, (1.0 - ny) * 0.5 * height};
  }
};

// Conservative pixel box: the sphere lies in its bounding cube aligned with the camera's basis, whose
// corners are all at view depths center depth +- r > near > 0, so its image lies in the box of the eight
// projected corners; one pixel of margin on every side.
PixelBox conservativeBox(const RayCamera& cam, const glm::dvec3& center, double r) {
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 corner =
        center + (i & 1 ? r : -r) * cam.right + (i & 2 ? r : -r) * cam.up + (i & 4 ? r : -r) * cam.forward;
    glm::dvec2 p = cam.project(corner);
    for (int a = 0; a < 2; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  auto first = [](double v, double size) { return int64_t(std::clamp(std::floor(v) - 1, 0.0, size)); };
  auto last = [](double v, double size) { return int64_t(std::clamp(std::floor(v) + 1, -1.0, size - 1)); };
  return {first(lo[0], cam.width), first(lo[1], cam.height), last(hi[0], cam.width), last(hi[1], cam.height)};
}

struct CpuSphere {
  glm::dvec3 center; // relative to the eye
  double radius;
  uint32_t color;
  uint32_t index;
  PixelBox box;
};

uint32_t packUnorm(double v) {
  return uint32_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

} // namespace

SphereRaycast raycastSpheres(const ParticleSet& set, const Camera& camera, uint32_t width, uint32_t height,
                             const SphereRaycastOptions& options) {
  validateCamera(camera);
  RayCamera cam;
  cam.width = width;
  cam.height = height;
  cam.eye = camera.eye;
  cam.forward = glm::normalize(camera.target - camera.eye);
  cam.right = glm::normalize(glm::cross(cam.forward, camera.up));
  cam.up = glm::cross(cam.right, cam.forward);
  cam.tanY = std::tan(glm::radians(camera.fovY) / 2);
  cam.tanX = cam.tanY * double(width) / double(height);
  double nearW = camera.nearW > 0 ? camera.nearW : defaultNear(sphereBounds(set));

  // Spheres relative to the eye (exact: set.origin - eye in double, plus the float offsets), culled.
  glm::dvec3 originFromEye = set.origin - camera.eye;
  RayCamera local = cam;
  local.eye = glm::dvec3(0);
  std::vector<CpuSphere> spheres;
  for (uint64_t i = 0; i < set.size(); ++i) {
    glm::dvec3 c = originFromEye + glm::dvec3(set.xyz[3 * i], set.xyz[3 * i + 1], set.xyz[3 * i + 2]);
    double r = set.radiusOf(i);
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z) || !(r > 0) || !std::isfinite(r))
      continue;
    if (!(glm::dot(c, cam.forward) - r > nearW)) continue;
    PixelBox box = options.bruteForce ? PixelBox{0, 0, int64_t(width) - 1, int64_t(height) - 1}
                                      : conservativeBox(local, c, r);
    if (box.x1 < box.x0 || box.y1 < box.y0) continue;
    spheres.push_back({c, r, set.colorOf(i), uint32_t(i), box});
  }

  // Spheres binned by bands of rows; bands run in parallel, each owning its pixels.
  uint32_t bands = (height + kBandRows - 1) / kBandRows;
  std::vector<std::vector<uint32_t>> bins(bands);
  for (uint32_t s = 0; s < spheres.size(); ++s)
    for (int64_t b = spheres[s].box.y0 / kBandRows; b <= spheres[s].box.y1 / kBandRows; ++b)
      bins[b].push_back(s);

  SphereRaycast out;
  out.width = width;
  out.height = height;
  uint64_t pixels = uint64_t(width) * height;
  out.image.assign(pixels, options.background);
  out.depth.assign(pixels, std::numeric_limits<double>::infinity());
  out.index.assign(pixels, kNoParticle);
  out.centrality.assign(pixels, 0.0f);
  std::vector<uint32_t> winner(pixels, kNoParticle); // position in `spheres`
  parallelBlocks(bands, 1, [&](uint64_t band, uint64_t, uint64_t) {
    int64_t rowBegin = int64_t(band) * kBandRows, rowEnd = std::min<int64_t>(rowBegin + kBandRows, height);
    for (uint32_t s : bins[band]) {
      const CpuSphere& sphere = spheres[s];
      for (int64_t y = std::max(rowBegin, sphere.box.y0); y <= std::min(rowEnd - 1, sphere.box.y1); ++y) {
        for (int64_t x = sphere.box.x0; x <= sphere.box.x1; ++x) {
          glm::dvec3 dir = local.ray(double(x) + 0.5, double(y) + 0.5);
          double a = glm::dot(dir, dir), b = glm::dot(sphere.center, dir);
          glm::dvec3 v = sphere.center - (b / a) * dir;
          double r2 = sphere.radius * sphere.radius;
          double disc = r2 - glm::dot(v, v);
          if (!(disc >= 0 && b > 0)) continue;
          double t = (glm::dot(sphere.center, sphere.center) - r2) / (b + std::sqrt(a * disc));
          uint64_t p = uint64_t(y) * width + uint64_t(x);
          if (t < out.depth[p] || (t == out.depth[p] && sphere.index < out.index[p])) {
            out.depth[p] = t;
            out.index[p] = sphere.index;
            out.centrality[p] = float(disc / r2);
            winner[p] = s;
          }
        }
      }
    }
    for (int64_t y = rowBegin; y < rowEnd; ++y) {
      for (uint32_t x = 0; x < width; ++x) {
        uint64_t p = uint64_t(y) * width + x;
        if (winner[p] == kNoParticle) continue;
        const CpuSphere& sphere = spheres[winner[p]];
        glm::dvec3 dir = local.ray(double(x) + 0.5, double(y) + 0.5);
        glm::dvec3 normal = glm::normalize(out.depth[p] * dir - sphere.center);
        double lambert = std::max(glm::dot(normal, glm::normalize(-dir)), 0.0);
        double shade = PR_SPHERE_AMBIENT + PR_SPHERE_DIFFUSE * lambert;
        uint32_t rgba = 0;
        for (int c = 0; c < 3; ++c)
          rgba |= packUnorm(double((sphere.color >> (8 * c)) & 0xFFu) / 255.0 * shade) << (8 * c);
        out.image[p] = rgba | (sphere.color & 0xFF000000u);
      }
    }
  });
  return out;
}

} // namespace pointrast

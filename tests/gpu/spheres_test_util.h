// Helpers of the sphere renderer tests: sets from hand-written spheres, rendering on the GPU and the CPU,
// and the agreement contract between them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "gpu_fixture.h"
#include "render/spheres/cpu_spheres.h"
#include "render/spheres/gpu_particles.h"
#include "render/spheres/sphere_renderer.h"

namespace pointrast::test {

constexpr uint32_t kBackground = 0xFF302010u;

struct SphereSpec {
  glm::dvec3 center;
  double radius;
  uint32_t color;
};

// A set from world spheres, positions relative to `origin`; radius and color per particle unless the
// global flags say they are all the same (then the first sphere's values become the global ones).
inline ParticleSet makeSet(const std::vector<SphereSpec>& spheres, bool globalRadius = false,
                           bool globalColor = false, glm::dvec3 origin = glm::dvec3(0)) {
  ParticleSet set;
  set.origin = origin;
  set.source = "test spheres";
  for (const SphereSpec& s : spheres) {
    glm::dvec3 p = s.center - origin;
    set.xyz.insert(set.xyz.end(), {float(p.x), float(p.y), float(p.z)});
    if (!globalRadius) set.radius.push_back(float(s.radius));
    if (!globalColor) set.colors.push_back(s.color);
    set.bounds.expand(s.center);
  }
  if (!spheres.empty()) {
    set.globalRadius = float(spheres[0].radius);
    set.globalColor = spheres[0].color;
  }
  return set;
}

inline std::vector<SphereSpec> randomSpheres(size_t count, uint64_t seed, double extent, double minRadius,
                                             double maxRadius) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), r(minRadius, maxRadius);
  std::vector<SphereSpec> spheres(count);
  for (SphereSpec& s : spheres)
    s = {{u(rng) * extent, u(rng) * extent * 0.6, u(rng) * extent * 0.4},
         r(rng),
         0xFF000000u | uint32_t(rng() & 0xFFFFFF)};
  return spheres;
}

struct GpuFrame {
  std::vector<uint32_t> image;
  std::vector<float> depth;
  std::vector<uint32_t> index;
  SphereStats stats;
};

inline GpuFrame renderGpu(gpu::Context& context, const ParticleSet& set, const Camera& camera, uint32_t w,
                          uint32_t h, ParticleUploadOptions upload = {}, SphereSettings settings = {}) {
  upload.progress = false;
  GpuParticles particles(context, set, upload);
  SphereRenderer renderer(context, w, h);
  settings.background = kBackground;
  GpuFrame frame;
  frame.stats = renderer.render(particles, camera, settings);
  frame.image = renderer.image();
  frame.depth = renderer.depth();
  frame.index = renderer.indices();
  return frame;
}

inline SphereRaycast renderCpu(const ParticleSet& set, const Camera& camera, uint32_t w, uint32_t h,
                               bool bruteForce = false) {
  SphereRaycastOptions options;
  options.background = kBackground;
  options.bruteForce = bruteForce;
  return raycastSpheres(set, camera, w, h, options);
}

inline bool colorsClose(uint32_t a, uint32_t b, int tolerance) {
  for (int c = 0; c < 4; ++c)
    if (std::abs(int((a >> (8 * c)) & 0xFF) - int((b >> (8 * c)) & 0xFF)) > tolerance) return false;
  return true;
}

// Pixels nearer to the silhouette than this (1 - (ray distance from the center / r)^2 below 1e-2, the
// outer 0.5 % of the disc radius) are excluded from the tight depth bound: there the depth moves with the
// square root of any error in the float32 sphere position, and float and double disagree beyond 1e-5.
constexpr float kGrazing = 1e-2f;

struct Comparison {
  uint64_t pixels = 0, agree = 0, bothHit = 0, lit = 0;
  uint64_t cpuOnly = 0, gpuOnly = 0;
  double maxRelDepth = 0;        // both hit, away from the silhouette
  double maxRelDepthGrazing = 0; // both hit, anywhere
  double agreement() const { return double(agree) / double(pixels); }
};

inline Comparison compare(const GpuFrame& gpu, const SphereRaycast& cpu) {
  Comparison c;
  c.pixels = gpu.image.size();
  for (size_t i = 0; i < gpu.image.size(); ++i) {
    bool gpuHit = gpu.index[i] != kNoParticle, cpuHit = cpu.index[i] != kNoParticle;
    c.lit += gpuHit || cpuHit;
    c.cpuOnly += cpuHit && !gpuHit;
    c.gpuOnly += gpuHit && !cpuHit;
    if (gpuHit != cpuHit) continue;
    if (!gpuHit) {
      c.agree += gpu.image[i] == kBackground && cpu.image[i] == kBackground;
      continue;
    }
    ++c.bothHit;
    c.agree += colorsClose(gpu.image[i], cpu.image[i], 1);
    double rel = std::abs(double(gpu.depth[i]) - cpu.depth[i]) / cpu.depth[i];
    c.maxRelDepthGrazing = std::max(c.maxRelDepthGrazing, rel);
    if (cpu.centrality[i] >= kGrazing) c.maxRelDepth = std::max(c.maxRelDepth, rel);
  }
  return c;
}

// The contract every comparison must meet; prints the figures.
inline void expectAgreement(const std::string& what, const GpuFrame& gpu, const SphereRaycast& cpu,
                            double minAgreement = 0.99) {
  Comparison c = compare(gpu, cpu);
  std::printf("%-44s %6.3f %% of pixels agree, %llu lit, %llu gpu-only, %llu cpu-only, depth error %.2e "
              "(%.2e at silhouettes), %llu large chunks, %llu spilled, %llu clamped\n",
              what.c_str(), 100 * c.agreement(), (unsigned long long)c.lit, (unsigned long long)c.gpuOnly,
              (unsigned long long)c.cpuOnly, c.maxRelDepth, c.maxRelDepthGrazing,
              (unsigned long long)gpu.stats.largeChunks, (unsigned long long)gpu.stats.spilledSpheres,
              (unsigned long long)gpu.stats.clampedSpheres);
  EXPECT_GE(c.agreement(), minAgreement) << what;
  EXPECT_GT(c.bothHit, 0u) << what << ": no sphere visible, the test would prove nothing";
  EXPECT_LE(c.maxRelDepth, 1e-5) << what;
  // At the silhouette the error is bounded by the float32 rounding of the sphere's position; a wrong
  // depth formula (e.g. the Euclidean distance) would be off by percents.
  EXPECT_LE(c.maxRelDepthGrazing, 1e-4) << what;
}

inline Camera lookAt(glm::dvec3 eye, glm::dvec3 target, double fov = 60) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.up = {0, 0, 1};
  c.fovY = fov;
  return c;
}

} // namespace pointrast::test

// Helpers of the sphere renderer tests: sets from hand-written spheres, rendering on the GPU and the CPU,
// and the agreement contract between them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "gpu_fixture.h"
#include "oracles/cpu_spheres.h"
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

// A frame of an existing renderer and upload (the background set to kBackground).
inline GpuFrame renderFrame(SphereRenderer& renderer, const GpuParticles& particles, const Camera& camera,
                            SphereSettings settings = {}) {
  settings.background = kBackground;
  GpuFrame frame;
  frame.stats = renderer.render(particles, camera, settings);
  frame.image = renderer.image();
  frame.depth = renderer.depth();
  frame.index = renderer.indices();
  return frame;
}

inline GpuFrame renderGpu(gpu::Context& context, const ParticleSet& set, const Camera& camera, uint32_t w,
                          uint32_t h, ParticleUploadOptions upload = {}, SphereSettings settings = {}) {
  upload.progress = false;
  GpuParticles particles(context, set, upload);
  SphereRenderer renderer(context, w, h);
  return renderFrame(renderer, particles, camera, settings);
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

// 400 spheres whose centers are just beyond an edge (left, right, above, below, in turn) of the frustum of
// axisCamera() at 160 x 120 pixels, each reaching into the image by up to its radius; radii of 0.01 to
// maxRadius times the depth (at depth d a pixel is d / 60 wide).
inline std::vector<SphereSpec> frustumEdgeSpheres(double maxRadius) {
  std::vector<SphereSpec> spheres;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1, 1), depth(2, 20), r(0.01, maxRadius);
  double aspect = 160.0 / 120.0;
  for (int i = 0; i < 400; ++i) {
    double d = depth(rng), radius = r(rng) * d, beyond = u(rng) * radius;
    glm::dvec3 c;
    switch (i % 4) {
    case 0:
      c = {-d * aspect - beyond, u(rng) * d, -d};
      break;
    case 1:
      c = {d * aspect + beyond, u(rng) * d, -d};
      break;
    case 2:
      c = {u(rng) * d * aspect, d + beyond, -d};
      break;
    default:
      c = {u(rng) * d * aspect, -d - beyond, -d};
      break;
    }
    spheres.push_back({c, radius, 0xFF000000u | uint32_t(rng() & 0xFFFFFF)});
  }
  return spheres;
}

// A pipeline that draws points (sphere-points, sphere-mesh-points) may lose the parts of spheres whose
// bounds are centered off-screen (Vulkan may discard a point whose vertex leaves the clip volume; lavapipe
// draws it through its guard band): with `pointsMayBeLost`, only expects it never to draw what the
// brute-force CPU ray caster does not; otherwise the whole contract. A sphere crossing the near plane is
// culled by every method.
inline void expectFrustumEdges(gpu::Context& context, const std::string& method,
                               const SphereSettings& settings, bool pointsMayBeLost) {
  Camera camera = axisCamera(); // 90 degrees, near 0.01
  std::vector<SphereSpec> spheres = frustumEdgeSpheres(0.08);
  spheres.push_back({{0.3, 0.2, -0.5}, 0.6, 0xFFFFFFFFu}); // crossing the near plane: culled
  ParticleSet set = makeSet(spheres);
  GpuFrame gpu = renderGpu(context, set, camera, 160, 120, {}, settings);
  SphereRaycast cpu = renderCpu(set, camera, 160, 120, true);
  Comparison c = compare(gpu, cpu);
  std::printf("%s frustum edges: %.3f %% of pixels agree, %llu cpu-only, %llu gpu-only of %llu lit\n",
              method.c_str(), 100 * c.agreement(), (unsigned long long)c.cpuOnly,
              (unsigned long long)c.gpuOnly, (unsigned long long)c.lit);
  EXPECT_EQ(c.gpuOnly, 0u) << method;
  EXPECT_EQ(std::count(gpu.index.begin(), gpu.index.end(), uint32_t(spheres.size() - 1)), 0) << method;
  if (!pointsMayBeLost) expectAgreement(method + " frustum edges", gpu, cpu);
}

// A sphere whose bounds exceed the device's largest point, and a small one in the corner. The image is a
// little larger than the largest point; at 90 degrees the big sphere's disc has a radius of 1.05
// half-images (r / d = sin(atan(1.05))), so its bounds are 1.05 images wide. With `clamps` (a pipeline of
// points) the method draws it clipped to a square of the largest point and counts it; otherwise it draws
// it whole and counts nothing.
inline void expectLargestPoint(gpu::Context& context, const std::string& method,
                               const SphereSettings& settings, bool clamps) {
  float maxPoint = context.properties().limits.pointSizeRange[1];
  uint32_t side = uint32_t(std::min(4096.0f, maxPoint + 64));
  ParticleSet set =
      makeSet({{{0, 0, -3}, 3 * std::sin(std::atan(1.05)), 0xFF80C0FFu}, {{8.1, 8.1, -9}, 0.2, 0xFF00FF00u}});
  Camera camera = axisCamera();
  GpuFrame gpu = renderGpu(context, set, camera, side, side, {}, settings);
  SphereRaycast cpu = renderCpu(set, camera, side, side);
  size_t big = std::count(cpu.index.begin(), cpu.index.end(), 0u);
  size_t drawn = std::count(gpu.index.begin(), gpu.index.end(), 0u);
  std::printf("%s: %u x %u image, largest point %.0f, big sphere on %zu of %zu pixels, %llu clamped\n",
              method.c_str(), side, side, maxPoint, drawn, big, (unsigned long long)gpu.stats.clampedSpheres);
  EXPECT_GT(std::count(gpu.index.begin(), gpu.index.end(), 1u), 0) << method;
  if (clamps) {
    EXPECT_EQ(gpu.stats.clampedSpheres, 1u) << method;
    EXPECT_LT(drawn, big) << method;
    EXPECT_GE(drawn, size_t(0.75 * maxPoint * maxPoint)) << method << ": the clamped square is drawn";
  } else {
    EXPECT_EQ(gpu.stats.clampedSpheres, 0u) << method;
    expectAgreement(method + " larger than the largest point", gpu, cpu);
  }
}

// Same spheres, same shading include: the method draws the same particle as sphere-compute nearly
// everywhere (ties of equal depth go to the lower index in compute, to the first drawn in hardware).
inline void expectAgreesWithSphereCompute(gpu::Context& context, const std::string& method,
                                          const SphereSettings& settings) {
  std::vector<SphereSpec> spheres = randomSpheres(4000, 19, 8, 0.1, 0.4);
  ParticleSet set = makeSet(spheres);
  Camera camera = lookAt({-10, -14, 7}, {0, 0, 0});
  GpuFrame other = renderGpu(context, set, camera, 200, 150, {}, settings);
  GpuFrame compute = renderGpu(context, set, camera, 200, 150);
  size_t same = 0;
  for (size_t i = 0; i < other.index.size(); ++i)
    same += other.index[i] == compute.index[i] && colorsClose(other.image[i], compute.image[i], 1);
  double fraction = double(same) / double(other.index.size());
  std::printf("%s vs sphere-compute: %.3f %% of pixels equal\n", method.c_str(), 100 * fraction);
  EXPECT_GE(fraction, 0.999) << method;
}

// 3000 random spheres (seed `seed`) in every particle layout, each with per-particle radius and color
// where the layout holds them and global ones where not, against the CPU; `label` + the layout's name
// names each. Returns the frames, in the order soa8, vec4x2, aos, xyz.
inline std::vector<GpuFrame> expectAgreementInEveryLayout(gpu::Context& context, const std::string& label,
                                                          const SphereSettings& settings, uint64_t seed) {
  std::vector<SphereSpec> spheres = randomSpheres(3000, seed, 10, 0.05, 0.6);
  Camera camera = lookAt({-14, -20, 9}, {0, 0, 0});
  ParticleSet perParticle = makeSet(spheres);
  ParticleSet globalBoth = makeSet(spheres, true, true);
  SphereRaycast cpuPerParticle = renderCpu(perParticle, camera, 192, 128);
  SphereRaycast cpuGlobal = renderCpu(globalBoth, camera, 192, 128);
  std::vector<GpuFrame> frames;
  for (ParticleLayout layout :
       {ParticleLayout::Soa8, ParticleLayout::Vec4x2, ParticleLayout::Aos, ParticleLayout::Xyz}) {
    bool global = !layoutHolds(layout, perParticle);
    ParticleUploadOptions upload;
    upload.layout = layout;
    frames.push_back(
        renderGpu(context, global ? globalBoth : perParticle, camera, 192, 128, upload, settings));
    expectAgreement(label + particleLayoutName(layout), frames.back(), global ? cpuGlobal : cpuPerParticle);
  }
  return frames;
}

} // namespace pointrast::test

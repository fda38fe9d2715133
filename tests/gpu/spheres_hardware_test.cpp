// The rasterization sphere pipelines (sphere-points, sphere-triangles, sphere-strip, sphere-geom) against
// the CPU ray caster, with the contract sphere-compute meets (spheres_compute_test.cpp): >= 99 % of pixels
// agree, depth within 1e-5 relative away from silhouettes; plus overlapping spheres, spheres across the
// image border and the frustum edges, every particle layout, and sphere-points' clamping to the device's
// largest point. Camera-aligned billboards meet the same contract and draw the same image as screen ones;
// so does conservative rasterization where the device has it. A method or option the device cannot run
// is skipped with the reason printed.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "gpu/context.h"
#include "spheres_test_util.h"

namespace pointrast::test {

namespace {

class SphereHardwareTest : public GpuTest, public ::testing::WithParamInterface<SphereMethod> {
protected:
  void SetUp() override {
    GpuTest::SetUp();
    std::string why;
    if (!SphereRenderer::supports(*context, GetParam(), &why)) {
      std::printf("skipped: %s\n", why.c_str());
      GTEST_SKIP() << why;
    }
  }
  SphereSettings settings() const {
    SphereSettings s;
    s.method = GetParam();
    return s;
  }
  std::string name(const std::string& what) const {
    return std::string(sphereMethodName(GetParam())) + " " + what;
  }
};

} // namespace

TEST_P(SphereHardwareTest, AgreesWithCpuInEveryLayout) {
  std::vector<SphereSpec> spheres = randomSpheres(3000, 7, 10, 0.05, 0.6);
  Camera camera = lookAt({-14, -20, 9}, {0, 0, 0});
  ParticleSet perParticle = makeSet(spheres);
  ParticleSet globalBoth = makeSet(spheres, true, true);
  SphereRaycast cpuPerParticle = renderCpu(perParticle, camera, 192, 128);
  SphereRaycast cpuGlobal = renderCpu(globalBoth, camera, 192, 128);
  for (ParticleLayout layout :
       {ParticleLayout::Soa8, ParticleLayout::Vec4x2, ParticleLayout::Aos, ParticleLayout::Xyz}) {
    bool global = !layoutHolds(layout, perParticle);
    ParticleUploadOptions upload;
    upload.layout = layout;
    GpuFrame gpu =
        renderGpu(*context, global ? globalBoth : perParticle, camera, 192, 128, upload, settings());
    expectAgreement(name(particleLayoutName(layout)), gpu, global ? cpuGlobal : cpuPerParticle);
  }
}

TEST_P(SphereHardwareTest, AgreesWithSphereCompute) {
  // Same spheres, same shading include: the same particle wins nearly everywhere (ties of equal depth go
  // to the lower index in compute, to the first drawn in hardware).
  std::vector<SphereSpec> spheres = randomSpheres(4000, 19, 8, 0.1, 0.4);
  ParticleSet set = makeSet(spheres);
  Camera camera = lookAt({-10, -14, 7}, {0, 0, 0});
  GpuFrame hw = renderGpu(*context, set, camera, 200, 150, {}, settings());
  GpuFrame compute = renderGpu(*context, set, camera, 200, 150);
  size_t same = 0;
  for (size_t i = 0; i < hw.index.size(); ++i)
    same += hw.index[i] == compute.index[i] && colorsClose(hw.image[i], compute.image[i], 1);
  double fraction = double(same) / double(hw.index.size());
  std::printf("%s vs sphere-compute: %.3f %% of pixels equal\n", sphereMethodName(GetParam()),
              100 * fraction);
  EXPECT_GE(fraction, 0.999);
}

TEST_P(SphereHardwareTest, OverlappingAndLargeSpheres) {
  // Disjoint and interpenetrating spheres, and one covering a quarter of the image (about 60 x 60 pixels:
  // within every device's point size limit of at least 64).
  std::vector<SphereSpec> spheres = {{{-1, 0.3, -6}, 1.0, 0xFF0000FFu},
                                     {{-0.4, 0, -9}, 1.5, 0xFF00FF00u},
                                     {{1.2, -0.5, -7}, 1.0, 0xFFFF0000u},
                                     {{2.0, -0.5, -7.4}, 1.0, 0xFF00FFFFu},
                                     {{0.5, 1.0, -12}, 2.5, 0xFFC0C0C0u}};
  Camera camera = axisCamera();
  camera.fovY = 60;
  GpuFrame gpu = renderGpu(*context, makeSet(spheres), camera, 160, 120, {}, settings());
  expectAgreement(name("overlap"), gpu, renderCpu(makeSet(spheres), camera, 160, 120));
  EXPECT_EQ(gpu.stats.clampedSpheres, 0u);
  for (uint32_t s = 0; s < spheres.size(); ++s)
    EXPECT_GT(std::count(gpu.index.begin(), gpu.index.end(), s), 100) << "sphere " << s;
}

TEST_P(SphereHardwareTest, SpheresAcrossTheBorderAndFrustumEdges) {
  // Spheres cut by the image edges, centers inside and outside the frustum, against the brute-force CPU
  // ray caster. Vulkan may discard a point whose vertex is outside the clip volume (lavapipe draws it
  // through its guard band), so sphere-points may lose the parts of spheres whose bounds are centered
  // off-screen, the known limit of that pipeline: it must only never draw what the CPU does not.
  Camera camera = axisCamera(); // 90 degrees, near 0.01
  std::vector<SphereSpec> spheres;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1, 1), depth(2, 20), r(0.01, 0.08);
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
  spheres.push_back({{0.3, 0.2, -0.5}, 0.6, 0xFFFFFFFFu}); // crossing the near plane: culled
  ParticleSet set = makeSet(spheres);
  GpuFrame gpu = renderGpu(*context, set, camera, 160, 120, {}, settings());
  SphereRaycast cpu = renderCpu(set, camera, 160, 120, true);
  Comparison c = compare(gpu, cpu);
  std::printf("%s frustum edges: %.3f %% of pixels agree, %llu cpu-only, %llu gpu-only of %llu lit\n",
              sphereMethodName(GetParam()), 100 * c.agreement(), (unsigned long long)c.cpuOnly,
              (unsigned long long)c.gpuOnly, (unsigned long long)c.lit);
  EXPECT_EQ(c.gpuOnly, 0u);
  EXPECT_EQ(std::count(gpu.index.begin(), gpu.index.end(), uint32_t(spheres.size() - 1)), 0);
  if (GetParam() != SphereMethod::Points) expectAgreement(name("frustum edges"), gpu, cpu);
}

TEST_P(SphereHardwareTest, PointsClampToTheLargestPoint) {
  // A sphere whose bounds exceed the device's largest point: sphere-points draws it clipped to a square
  // of that size and counts it; every other pipeline draws it whole. The image is a little larger than
  // the largest point; at 90 degrees the sphere's disc has a radius of 1.05 half-images (r / d =
  // sin(atan(1.05))), so its bounds are 1.05 images wide, and a small sphere shows in the corner.
  float maxPoint = context->properties().limits.pointSizeRange[1];
  uint32_t side = uint32_t(std::min(4096.0f, maxPoint + 64));
  ParticleSet set =
      makeSet({{{0, 0, -3}, 3 * std::sin(std::atan(1.05)), 0xFF80C0FFu}, {{8.1, 8.1, -9}, 0.2, 0xFF00FF00u}});
  Camera camera = axisCamera();
  GpuFrame gpu = renderGpu(*context, set, camera, side, side, {}, settings());
  SphereRaycast cpu = renderCpu(set, camera, side, side);
  size_t big = std::count(cpu.index.begin(), cpu.index.end(), 0u);
  size_t drawn = std::count(gpu.index.begin(), gpu.index.end(), 0u);
  std::printf("%s: %u x %u image, largest point %.0f, big sphere on %zu of %zu pixels, %llu clamped\n",
              sphereMethodName(GetParam()), side, side, maxPoint, drawn, big,
              (unsigned long long)gpu.stats.clampedSpheres);
  EXPECT_GT(std::count(gpu.index.begin(), gpu.index.end(), 1u), 0);
  if (GetParam() == SphereMethod::Points) {
    EXPECT_EQ(gpu.stats.clampedSpheres, 1u);
    EXPECT_LT(drawn, big);
    EXPECT_GE(drawn, size_t(0.75 * maxPoint * maxPoint)) << "the clamped square is drawn";
  } else {
    EXPECT_EQ(gpu.stats.clampedSpheres, 0u);
    expectAgreement(name("larger than the largest point"), gpu, cpu);
  }
}

TEST_P(SphereHardwareTest, CameraBillboardsAgreeWithCpuInEveryLayout) {
  std::vector<SphereSpec> spheres = randomSpheres(3000, 23, 10, 0.05, 0.6);
  Camera camera = lookAt({-14, -20, 9}, {0, 0, 0});
  ParticleSet perParticle = makeSet(spheres);
  ParticleSet globalBoth = makeSet(spheres, true, true);
  SphereRaycast cpuPerParticle = renderCpu(perParticle, camera, 192, 128);
  SphereRaycast cpuGlobal = renderCpu(globalBoth, camera, 192, 128);
  SphereSettings s = settings();
  s.billboard = SphereBillboard::Camera;
  for (ParticleLayout layout :
       {ParticleLayout::Soa8, ParticleLayout::Vec4x2, ParticleLayout::Aos, ParticleLayout::Xyz}) {
    bool global = !layoutHolds(layout, perParticle);
    ParticleUploadOptions upload;
    upload.layout = layout;
    GpuFrame gpu = renderGpu(*context, global ? globalBoth : perParticle, camera, 192, 128, upload, s);
    expectAgreement(name(std::string("camera billboards ") + particleLayoutName(layout)), gpu,
                    global ? cpuGlobal : cpuPerParticle);
  }
}

namespace {

// Large spheres close to the eye of a 90-degree view, out to the image edges, where perspective widens a
// sphere's projection most beyond its radius: a camera-aligned square of side 2r would miss up to half of
// the disc at the corners (the square needs a half side of 1.9 r there). Centers stay in the image, so
// sphere-points draws every sphere too.
std::vector<SphereSpec> wideViewSpheres() {
  std::vector<SphereSpec> spheres;
  const double aspect = 160.0 / 120.0;
  uint32_t color = 0xFF204080u;
  for (double d : {4.0, 9.0})
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 4; ++j) {
        double x = (-0.85 + 1.7 * i / 4) * aspect * d, y = (-0.85 + 1.7 * j / 3) * d;
        spheres.push_back({{x + (d > 5 ? 1.1 : 0), y, -d}, d > 5 ? 1.6 : 1.0, color});
        color = color * 2654435761u | 0xFF000000u;
      }
  return spheres;
}

} // namespace

TEST_P(SphereHardwareTest, CameraBillboardsDrawWhatScreenBillboardsDraw) {
  // The same fragment shader decides every pixel, so as long as both impostors contain every pixel center
  // the sphere covers, the images are identical; a camera square too small under perspective loses pixels
  // at the silhouettes farthest from the image center.
  ParticleSet set = makeSet(wideViewSpheres());
  Camera camera = axisCamera();
  SphereSettings s = settings();
  GpuFrame screen = renderGpu(*context, set, camera, 160, 120, {}, s);
  s.billboard = SphereBillboard::Camera;
  GpuFrame cam = renderGpu(*context, set, camera, 160, 120, {}, s);
  size_t differ = 0;
  for (size_t i = 0; i < screen.index.size(); ++i)
    differ += screen.index[i] != cam.index[i] || screen.image[i] != cam.image[i];
  std::printf("%s: camera vs screen billboards differ on %zu pixels\n", sphereMethodName(GetParam()), differ);
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(cam.stats.clampedSpheres, 0u);
  expectAgreement(name("camera billboards, wide view"), cam, renderCpu(set, camera, 160, 120));
}

TEST_P(SphereHardwareTest, ConservativeRasterizationDrawsTheSameImage) {
  SphereSettings s = settings();
  s.conservative = true;
  std::string why;
  if (!SphereRenderer::supports(*context, s, &why)) {
    std::printf("skipped: %s\n", why.c_str());
    GTEST_SKIP() << why;
  }
  ParticleSet set = makeSet(wideViewSpheres());
  Camera camera = axisCamera();
  SphereRaycast cpu = renderCpu(set, camera, 160, 120);
  for (SphereBillboard billboard : {SphereBillboard::Screen, SphereBillboard::Camera}) {
    s.billboard = billboard;
    s.conservative = false;
    GpuFrame plain = renderGpu(*context, set, camera, 160, 120, {}, s);
    s.conservative = true;
    GpuFrame conservative = renderGpu(*context, set, camera, 160, 120, {}, s);
    size_t differ = 0;
    for (size_t i = 0; i < plain.index.size(); ++i)
      differ += plain.index[i] != conservative.index[i] || plain.image[i] != conservative.image[i];
    EXPECT_EQ(differ, 0u) << sphereBillboardName(billboard);
    expectAgreement(name(std::string("conservative, ") + sphereBillboardName(billboard) + " billboards"),
                    conservative, cpu);
  }
}

INSTANTIATE_TEST_SUITE_P(Spheres, SphereHardwareTest,
                         ::testing::Values(SphereMethod::Points, SphereMethod::Triangles, SphereMethod::Strip,
                                           SphereMethod::Geometry),
                         [](const ::testing::TestParamInfo<SphereMethod>& param) {
                           std::string n = sphereMethodName(param.param);
                           std::replace(n.begin(), n.end(), '-', '_');
                           return n;
                         });

} // namespace pointrast::test

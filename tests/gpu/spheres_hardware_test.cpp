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
  expectAgreementInEveryLayout(*context, name(""), settings(), 7);
}

TEST_P(SphereHardwareTest, AgreesWithSphereCompute) {
  expectAgreesWithSphereCompute(*context, sphereMethodName(GetParam()), settings());
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
  expectFrustumEdges(*context, sphereMethodName(GetParam()), settings(),
                     /* pointsMayBeLost= */ GetParam() == SphereMethod::Points);
}

TEST_P(SphereHardwareTest, PointsClampToTheLargestPoint) {
  // sphere-points draws the sphere clipped to a square of the largest point; every other pipeline whole.
  expectLargestPoint(*context, sphereMethodName(GetParam()), settings(),
                     /* clamps= */ GetParam() == SphereMethod::Points);
}

TEST_P(SphereHardwareTest, CameraBillboardsAgreeWithCpuInEveryLayout) {
  SphereSettings s = settings();
  s.billboard = SphereBillboard::Camera;
  expectAgreementInEveryLayout(*context, name("camera billboards "), s, 23);
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

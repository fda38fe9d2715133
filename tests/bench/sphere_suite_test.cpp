// The sphere suite's orbit cameras (bench/views.h), checked on the CPU with the camera contract of
// docs/design.md on the generated particle scenes: the short orbit's eyes are inside the spheres' bounds and
// see part of the set, the long orbit's are outside and see every sphere whole; both are a function of
// the bounds alone. Plus the spheres2023 suite's data sets and combinations, and how a combination's
// errors become results (measureGuarded, shared with the point runner).
#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "base/error.h"
#include "bench/sphere_runner.h"
#include "bench/suites.h"
#include "bench/views.h"
#include "cloud/particles_generate.h"
#include "render/spheres/spheres.h"

namespace {

using namespace pointrast;

constexpr uint32_t kWidth = 320, kHeight = 180;
constexpr double kAspect = double(kWidth) / kHeight;

struct Seen {
  uint64_t centers = 0; // sphere centers in front of the near plane whose pixel is in the image
  uint64_t whole = 0;   // spheres entirely in front of the eye and inside the image
};

// With the renderer's projection relative to the origin; a sphere is "whole" when the pixel box of its
// eight bounding-cube corners lies in the image.
Seen seen(const ParticleSet& set, const Camera& camera) {
  const glm::dvec3 origin = set.origin;
  const glm::dmat4 vp = viewProjection(camera, origin, kAspect);
  const double nearW = defaultNear(sphereBounds(set));
  auto pixel = [&](glm::dvec3 p, double& px, double& py) {
    glm::dvec4 c = vp * glm::dvec4(p - origin, 1.0);
    if (!(c.w > nearW)) return false;
    px = (c.x / c.w + 1) / 2 * kWidth;
    py = (1 - c.y / c.w) / 2 * kHeight;
    return true;
  };
  Seen s;
  for (uint64_t i = 0; i < set.size(); ++i) {
    const glm::dvec3 center = set.world(i);
    double px, py;
    if (pixel(center, px, py) && px >= 0 && px < kWidth && py >= 0 && py < kHeight) ++s.centers;
    bool whole = true;
    const double r = set.radiusOf(i);
    for (int corner = 0; corner < 8 && whole; ++corner) {
      glm::dvec3 p = center + r * glm::dvec3(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
      whole = pixel(p, px, py) && px >= 0 && px <= kWidth && py >= 0 && py <= kHeight;
    }
    s.whole += whole;
  }
  return s;
}

bool inside(const Bounds& b, glm::dvec3 p) {
  for (int a = 0; a < 3; ++a)
    if (!(p[a] >= b.min[a] && p[a] <= b.max[a])) return false;
  return true;
}

class Orbits : public ::testing::TestWithParam<ParticleScene> {
protected:
  static ParticleSet setFor(ParticleScene scene) {
    ParticleGenerateOptions options;
    options.particles = 20'000;
    options.progress = false;
    return generateParticles(scene, options);
  }
};

TEST_P(Orbits, ShortOrbitIsInsideTheBoundsAndSeesPartOfTheSet) {
  const ParticleSet set = setFor(GetParam());
  const Bounds bounds = sphereBounds(set);
  const std::vector<Camera> cameras = bench::orbitCameras(bench::Orbit::Short, bounds, kAspect);
  ASSERT_EQ(cameras.size(), 10u);
  for (size_t k = 0; k < cameras.size(); ++k) {
    const Camera& c = cameras[k];
    EXPECT_NO_THROW(validateCamera(c)) << k;
    EXPECT_TRUE(inside(bounds, c.eye)) << "camera " << k << " " << describeCamera(c);
    EXPECT_EQ(c.target, bounds.center());
    for (size_t j = 0; j < k; ++j)
      EXPECT_GT(glm::length(c.eye - cameras[j].eye), 1e-6 * bounds.diagonal()) << k << " equals " << j;
    const Seen s = seen(set, c);
    EXPECT_GT(s.centers, 0u) << "camera " << k << " sees nothing";
    EXPECT_LT(s.centers, set.size()) << "camera " << k << " sees everything: it is not inside";
  }
}

TEST_P(Orbits, LongOrbitIsOutsideTheBoundsAndSeesEverySphereWhole) {
  const ParticleSet set = setFor(GetParam());
  const Bounds bounds = sphereBounds(set);
  const std::vector<Camera> cameras = bench::orbitCameras(bench::Orbit::Long, bounds, kAspect);
  ASSERT_EQ(cameras.size(), 10u);
  for (size_t k = 0; k < cameras.size(); ++k) {
    const Camera& c = cameras[k];
    EXPECT_NO_THROW(validateCamera(c)) << k;
    EXPECT_FALSE(inside(bounds, c.eye)) << "camera " << k << " " << describeCamera(c);
    EXPECT_GT(glm::length(c.eye - bounds.center()), 0.5 * bounds.diagonal())
        << "outside the enclosing sphere";
    const Seen s = seen(set, c);
    EXPECT_EQ(s.whole, set.size()) << "camera " << k << " cuts spheres off";
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, Orbits,
                         ::testing::Values(ParticleScene::Block, ParticleScene::Drops, ParticleScene::Laser,
                                           ParticleScene::Uniform),
                         [](const auto& p) {
                           std::string name = particleSceneName(p.param);
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

TEST(OrbitsFromBounds, DeterministicEvenlySpacedAndValidForDegenerateBounds) {
  Bounds box;
  box.expand(glm::dvec3(10, 20, 30));
  box.expand(glm::dvec3(110, 70, 35));
  Bounds flat;
  flat.expand(glm::dvec3(0, 0, 0));
  flat.expand(glm::dvec3(0, 50, 0));
  Bounds point;
  point.expand(glm::dvec3(5, 5, 5));
  for (bench::Orbit o : bench::allOrbits()) {
    std::vector<Camera> a = bench::orbitCameras(o, box, 1.6), b = bench::orbitCameras(o, box, 1.6);
    ASSERT_EQ(a.size(), 10u);
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].eye, b[k].eye);
      EXPECT_EQ(a[k].target, b[k].target);
      // Evenly spaced: every eye at the same height, one tenth of a turn from the last.
      EXPECT_NEAR(a[k].eye.z, a[0].eye.z, 1e-9);
      const glm::dvec2 p = glm::dvec2(a[k].eye - box.center()),
                       q = glm::dvec2(a[(k + 1) % 10].eye - box.center());
      if (o == bench::Orbit::Long) {
        EXPECT_NEAR(std::acos(glm::dot(p, q) / (glm::length(p) * glm::length(q))), 2 * std::numbers::pi / 10,
                    1e-9);
      }
    }
    for (const Bounds* degenerate : {&flat, &point})
      for (const Camera& c : bench::orbitCameras(o, *degenerate, 1.6, 60, 3))
        EXPECT_NO_THROW(validateCamera(c)) << bench::orbitName(o);
  }
  EXPECT_EQ(bench::orbitCameras(bench::Orbit::Short, box, 1.6, 60, 4).size(), 4u);
}

TEST(OrbitsFromBounds, NamesRoundTrip) {
  for (bench::Orbit o : bench::allOrbits())
    EXPECT_EQ(bench::parseOrbit(bench::orbitName(o)), o);
  EXPECT_THROW(bench::parseOrbit("medium"), InputError);
}

TEST(Spheres2023, DataSetsAtTheStudySizes) {
  ASSERT_TRUE(bench::isSphereSuite("spheres2023"));
  EXPECT_FALSE(bench::isSphereSuite("paper2021"));
  std::vector<bench::Dataset> full = bench::sphereSuiteDatasets("spheres2023", 1.0, 1);
  ASSERT_EQ(full.size(), 4u);
  EXPECT_EQ(full[0].points, 306'000'000u);
  EXPECT_EQ(full[1].points, 4'000'000u);
  EXPECT_EQ(full[2].points, 30'000'000u);
  EXPECT_EQ(full[3].points, 200'000'000u);
  EXPECT_EQ(full[0].label, "laser-like (particles-laser, 306M)");
  EXPECT_EQ(full[1].source, "particles-block");
  for (const bench::Dataset& d : full)
    EXPECT_TRUE(isParticleSceneName(d.source)) << d.source;
  std::vector<bench::Dataset> smoke = bench::sphereSuiteDatasets("spheres2023", 0.0001, 1);
  EXPECT_EQ(smoke[0].points, 30'600u);
  EXPECT_EQ(smoke[1].points, 1'000u) << "at least 1000 particles";
  EXPECT_THROW(bench::sphereSuiteDatasets("spheres2023", 0.0, 1), InputError);
  EXPECT_THROW(bench::sphereSuiteDatasets("spheres1999", 1.0, 1), InputError);
  EXPECT_THROW(bench::suiteDatasets("spheres2023", 1.0, 1), InputError) << "no point data sets";
}

TEST(Spheres2023, CombinationsCoverEveryMethodOfTheTable) {
  bench::SphereBenchConfig config;
  config.billboards = {SphereBillboard::Screen, SphereBillboard::Camera};
  config.conservative = {false, true};
  std::vector<bench::SphereResult> all = bench::sphereCombinations(config);
  size_t expected = 0;
  for (const SphereMethodInfo& m : sphereMethodTable()) {
    const size_t n =
        std::count_if(all.begin(), all.end(), [&](const auto& r) { return r.method == m.method; });
    EXPECT_EQ(n, sphereMethodTakesBillboards(m.method) ? 4u : 1u) << m.name;
    expected += n;
  }
  EXPECT_EQ(all.size(), expected);
  EXPECT_FALSE(sphereMethodTakesBillboards(SphereMethod::Compute));
  EXPECT_TRUE(sphereMethodTakesBillboards(SphereMethod::Strip));
  config.methods = {SphereMethod::Compute, SphereMethod::Triangles};
  config.conservative = {false};
  EXPECT_EQ(bench::sphereCombinations(config).size(), 3u);
}

TEST(MeasureGuarded, ErrorsBecomeStatusesAndADeviceFaultEndsTheRun) {
  bench::SphereResult r;
  int recorded = 0;
  auto record = [&](const bench::SphereResult& faulted) {
    EXPECT_EQ(faulted.status, "device-fault");
    ++recorded;
  };
  bench::measureGuarded(
      r, [] { throw UnsupportedError("no mesh shaders"); }, record);
  EXPECT_EQ(r.status, "unsupported");
  EXPECT_EQ(r.reason, "no mesh shaders");
  bench::SphereResult big;
  bench::measureGuarded(
      big, [] { throw InputError("more than 4.29 G particles"); }, record);
  EXPECT_EQ(big.status, "unsupported");
  bench::SphereResult fine;
  bench::measureGuarded(
      fine, [&] { fine.cameraMs.push_back(1.5); }, record);
  EXPECT_TRUE(fine.ok());
  EXPECT_EQ(recorded, 0);
  bench::SphereResult stuck;
  EXPECT_THROW(bench::measureGuarded(
                   stuck, [] { throw DeviceFault("the GPU did not finish"); }, record),
               DeviceFault);
  EXPECT_EQ(stuck.status, "device-fault");
  EXPECT_EQ(stuck.reason, "the GPU did not finish");
  EXPECT_EQ(recorded, 1);
}

} // namespace

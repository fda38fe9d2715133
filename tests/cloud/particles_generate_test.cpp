#include "cloud/particles_generate.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "base/error.h"
#include "cloud/particle_scenes.h"
#include "cloud/test_clouds.h"

namespace pointrast {
namespace {

ParticleSet generate(ParticleScene scene, uint64_t n, uint64_t seed = 1, bool perParticleRadius = false,
                     float radius = 0.5f) {
  ParticleGenerateOptions options;
  options.particles = n;
  options.seed = seed;
  options.radius = radius;
  options.perParticleRadius = perParticleRadius;
  options.progress = false;
  return generateParticles(scene, options);
}

constexpr ParticleScene kScenes[] = {ParticleScene::Block, ParticleScene::Drops, ParticleScene::Laser,
                                     ParticleScene::Uniform};

TEST(ParticleSceneNames, RoundTripAndHelpfulError) {
  for (ParticleScene s : kScenes) {
    EXPECT_EQ(parseParticleScene(particleSceneName(s)), s);
    EXPECT_TRUE(isParticleSceneName(particleSceneName(s)));
  }
  EXPECT_STREQ(particleSceneName(ParticleScene::Laser), "particles-laser");
  EXPECT_FALSE(isParticleSceneName("terrain"));
  EXPECT_FALSE(isParticleSceneName("particles-"));
  try {
    parseParticleScene("particles-foam");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    for (ParticleScene s : kScenes)
      EXPECT_NE(std::string(e.what()).find(particleSceneName(s)), std::string::npos) << e.what();
  }
}

TEST(GenerateParticles, RefusesBadRadiiAndCountsThatCannotBeHeld) {
  for (float r : {0.0f, -1.0f, NAN, INFINITY})
    EXPECT_THROW(generate(ParticleScene::Uniform, 10, 1, false, r), InputError) << r;
  EXPECT_THROW(generate(ParticleScene::Block, (uint64_t(1) << 40) + 1), InputError);
  // 2^39 particles need 8 TiB: more than the memory of any machine running these tests.
  EXPECT_THROW(generate(ParticleScene::Laser, uint64_t(1) << 39), InputError);
}

class EachParticleScene : public ::testing::TestWithParam<ParticleScene> {};

TEST_P(EachParticleScene, ExactCountMemoryBoundsAndSource) {
  for (uint64_t n : {uint64_t(0), uint64_t(1), uint64_t(2), uint64_t(19), uint64_t(1000), uint64_t(123457)}) {
    const ParticleSet set = generate(GetParam(), n);
    ASSERT_EQ(set.size(), n);
    ASSERT_EQ(set.xyz.size(), 3 * n);
    ASSERT_EQ(set.colors.size(), n); // 16 B per particle: no radius array unless asked for
    EXPECT_TRUE(set.radius.empty());
    EXPECT_EQ(set.globalRadius, 0.5f);
    EXPECT_EQ(set.origin, glm::dvec3(0));
    EXPECT_EQ(set.source,
              std::string(particleSceneName(GetParam())) + ", " + std::to_string(n) + " particles, seed 1");
    if (n == 0) {
      EXPECT_TRUE(set.bounds.empty());
      continue;
    }
    Bounds ref;
    for (uint64_t i = 0; i < n; ++i) {
      const glm::dvec3 p = set.world(i);
      ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << "particle " << i;
      ref.expand(p);
    }
    EXPECT_EQ(set.bounds.min, ref.min);
    EXPECT_EQ(set.bounds.max, ref.max);
  }
}

TEST_P(EachParticleScene, DeterministicPerSeedDifferentAcrossSeeds) {
  const ParticleSet a = generate(GetParam(), 30'000, 7), b = generate(GetParam(), 30'000, 7);
  const ParticleSet c = generate(GetParam(), 30'000, 8);
  EXPECT_EQ(a.xyz, b.xyz);
  EXPECT_EQ(a.colors, b.colors);
  EXPECT_NE(a.xyz, c.xyz);
}

TEST_P(EachParticleScene, EveryParticleIsAFunctionOfItsIndexAlone) {
  // generateParticles cuts the work into blocks run on every hardware thread; any range computed alone,
  // in one thread, must give the same particles. Ranges straddle the 65536-particle blocks and the
  // scenes' components (lattice, clusters, gas).
  const uint64_t n = 200'000;
  const ParticleSet set = generate(GetParam(), n, 3, true);
  auto scene = detail::makeParticleGenerator(GetParam(), n, 3, 0.5f);
  const std::pair<uint64_t, uint64_t> ranges[] = {{0, 1},        {65535, 3},          {131000, 1100},
                                                  {12345, 1},    {n * 7 / 8 - 5, 10}, {n * 19 / 20 - 5, 10},
                                                  {n - 777, 777}};
  for (auto [first, count] : ranges) {
    std::vector<float> xyz(3 * count), radius(count);
    std::vector<uint32_t> colors(count);
    scene->generate(first, count, xyz.data(), colors.data(), radius.data());
    for (uint64_t k = 0; k < count; ++k) {
      ASSERT_EQ(colors[k], set.colors[first + k]) << "particle " << first + k;
      ASSERT_EQ(radius[k], set.radius[first + k]) << "particle " << first + k;
      for (int a = 0; a < 3; ++a)
        ASSERT_EQ(xyz[3 * k + a], set.xyz[3 * (first + k) + a]) << "particle " << first + k;
    }
  }
}

TEST_P(EachParticleScene, PerParticleRadiiVaryAroundTheRadiusAndLeaveTheRestAlone) {
  const ParticleSet global = generate(GetParam(), 50'000, 5, false, 0.4f);
  const ParticleSet per = generate(GetParam(), 50'000, 5, true, 0.4f);
  EXPECT_EQ(per.xyz, global.xyz);
  EXPECT_EQ(per.colors, global.colors);
  ASSERT_EQ(per.radius.size(), per.size());
  double sum = 0;
  std::set<float> distinct;
  for (float r : per.radius) {
    ASSERT_GT(r, 0.1f);
    ASSERT_LT(r, 0.7f);
    sum += r;
    if (distinct.size() < 100) distinct.insert(r);
  }
  EXPECT_NEAR(sum / double(per.size()), 0.4, 0.05);
  EXPECT_GE(distinct.size(), 100u);
  const RadiusRange range = radiusRange(per);
  EXPECT_EQ(range.min, *std::min_element(per.radius.begin(), per.radius.end()));
  EXPECT_EQ(range.max, *std::max_element(per.radius.begin(), per.radius.end()));
}

TEST_P(EachParticleScene, ColorsAreOpaqueAndVaried) {
  const ParticleSet set = generate(GetParam(), 100'000);
  std::set<uint32_t> distinct;
  for (uint32_t c : set.colors) {
    ASSERT_EQ(c >> 24, 255u);
    if (distinct.size() < 20) distinct.insert(c);
  }
  EXPECT_GE(distinct.size(), 20u);
}

INSTANTIATE_TEST_SUITE_P(Scenes, EachParticleScene, ::testing::ValuesIn(kScenes), [](const auto& param) {
  std::string name = particleSceneName(param.param);
  return name.substr(name.find('-') + 1);
});

// Fraction of particles whose nearest neighbor (within a 3-unit grid search) lies closer than `within`.
double denseFraction(const ParticleSet& set, double within) {
  std::multimap<std::tuple<int, int, int>, uint64_t> grid;
  auto cell = [&](const glm::dvec3& p) {
    return std::make_tuple(int(std::floor(p.x / 3)), int(std::floor(p.y / 3)), int(std::floor(p.z / 3)));
  };
  for (uint64_t i = 0; i < set.size(); ++i)
    grid.emplace(cell(set.world(i)), i);
  uint64_t dense = 0;
  for (uint64_t i = 0; i < set.size(); ++i) {
    const glm::dvec3 p = set.world(i);
    auto [cx, cy, cz] = cell(p);
    bool found = false;
    for (int dx = -1; dx <= 1 && !found; ++dx)
      for (int dy = -1; dy <= 1 && !found; ++dy)
        for (int dz = -1; dz <= 1 && !found; ++dz) {
          auto [lo, hi] = grid.equal_range({cx + dx, cy + dy, cz + dz});
          for (auto it = lo; it != hi && !found; ++it)
            found = it->second != i && glm::length(set.world(it->second) - p) < within;
        }
    dense += found;
  }
  return double(dense) / double(set.size());
}

TEST(ParticleScenes, DensePhasesHoldMostParticlesAtTheirSpacing) {
  // Lattices, liquids and clusters put neighbors about 1 apart; gas and vapor are far sparser.
  EXPECT_GT(denseFraction(generate(ParticleScene::Block, 40'000), 1.5), 0.88);
  EXPECT_GT(denseFraction(generate(ParticleScene::Drops, 40'000), 1.5), 0.9);
  EXPECT_GT(denseFraction(generate(ParticleScene::Laser, 40'000), 1.5), 0.9);
}

TEST(ParticleScenes, BlockIsALatticeBetweenTwoVaporRegions) {
  const ParticleSet set = generate(ParticleScene::Block, 100'000);
  // 90% lattice in a 2:1:1 block; the vapor extends the tube along x on both sides.
  const glm::dvec3 size = set.bounds.size();
  EXPECT_NEAR(size.y, size.z, 2.0);
  EXPECT_GT(size.x, 4 * size.y);
  uint64_t left = 0, right = 0;
  for (uint64_t i = 90'000; i < set.size(); ++i)
    (set.world(i).x < 0 ? left : right)++;
  EXPECT_GT(left, 4000u);
  EXPECT_GT(right, 4000u);
}

TEST(ParticleScenes, LaserHasASlabBelowAndAPlumeAbove) {
  const ParticleSet set = generate(ParticleScene::Laser, 80'000);
  uint64_t below = 0, high = 0;
  Bounds slab;
  for (uint64_t i = 0; i < set.size(); ++i) {
    const glm::dvec3 p = set.world(i);
    below += p.z < 1.0;
    high += p.z > 5.0;
    if (p.z < 0) slab.expand(p);
  }
  EXPECT_NEAR(double(below) / double(set.size()), 7.0 / 8.0, 0.02);
  EXPECT_GT(high, set.size() / 10);
  EXPECT_NEAR(slab.size().x, slab.size().y, 2.0);
  EXPECT_LT(slab.size().z, slab.size().x / 2); // a slab, not a cube
  EXPECT_GT(set.bounds.max.z, slab.size().x);  // the plume rises higher than the slab is wide
}

TEST(ParticleScenes, UniformFillsACubeAtUnitDensity) {
  const ParticleSet set = generate(ParticleScene::Uniform, 1'000'000);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(set.bounds.size()[a], 100.0, 0.1);
    EXPECT_NEAR(set.bounds.center()[a], 0.0, 0.1);
  }
}

// ---- helpers beside ParticleSet ----------------------------------------------------------------------

TEST(ParticleSetHelpers, BoundsAndSphereBounds) {
  ParticleSet set;
  set.origin = glm::dvec3(1000, 2000, 3000);
  set.xyz = {0, 0, 0, 1, -2, 3, -0.5f, 4, 1};
  set.globalRadius = 0.25f;
  computeBounds(set);
  EXPECT_EQ(set.bounds.min, glm::dvec3(999.5, 1998, 3000));
  EXPECT_EQ(set.bounds.max, glm::dvec3(1001, 2004, 3003));
  Bounds spheres = sphereBounds(set);
  EXPECT_EQ(spheres.min, glm::dvec3(999.25, 1997.75, 2999.75));
  EXPECT_EQ(spheres.max, glm::dvec3(1001.25, 2004.25, 3003.25));
  EXPECT_EQ(radiusRange(set).min, 0.25f);
  set.radius = {1, 0.5f, 2};
  spheres = sphereBounds(set);
  EXPECT_EQ(spheres.min, glm::dvec3(997.5, 1997.5, 2999));
  EXPECT_EQ(spheres.max, glm::dvec3(1001.5, 2006, 3003.5));
  EXPECT_EQ(radiusRange(set).min, 0.5f);
  EXPECT_EQ(radiusRange(set).max, 2.0f);
  EXPECT_TRUE(sphereBounds(ParticleSet{}).empty());
}

TEST(ParticleSetHelpers, PointsAsSpheresKeepPrecisionAndColors) {
  // UTM-like offsets: the set is relative to the cloud's origin, so millimetres survive the float.
  PointCloud cloud = testing::randomCloud(50'000, 1'000'000, glm::dvec3(500000, 4000000, 100));
  cloud.colors.assign(cloud.size(), packRgba(10, 20, 30));
  cloud.colors[7] = packRgba(200, 100, 50);
  const ParticleSet set = particlesFromCloud(cloud, 0.05f);
  ASSERT_EQ(set.size(), cloud.size());
  EXPECT_EQ(set.globalRadius, 0.05f);
  EXPECT_TRUE(set.radius.empty());
  EXPECT_EQ(set.origin, cloud.origin());
  for (uint64_t i = 0; i < cloud.size(); ++i)
    ASSERT_LT(glm::length(set.world(i) - cloud.world(i)), 1e-4) << i;
  EXPECT_EQ(set.colors[7], packRgba(200, 100, 50));
  EXPECT_EQ(set.colors[8], packRgba(10, 20, 30));
  EXPECT_LT(glm::length(set.bounds.min - cloud.bounds.min), 1e-4);
  EXPECT_LT(glm::length(set.bounds.max - cloud.bounds.max), 1e-4);
  // Without RGB the points get the elevation ramp, as the point renderers show them.
  PointCloud plain = testing::randomCloud(1000);
  const ParticleSet ramp = particlesFromCloud(plain, 1.0f);
  std::vector<uint32_t> expected(plain.size());
  displayColors(expected.data(), plain, 0, plain.size());
  EXPECT_EQ(ramp.colors, expected);
}

} // namespace
} // namespace pointrast

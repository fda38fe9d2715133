#include "cloud/generate.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "base/error.h"
#include "cloud/order.h"
#include "cloud/scene.h"

namespace pointrast {
namespace {

PointCloud generate(Scene scene, uint64_t points, uint64_t seed = 1) {
  GenerateOptions options;
  options.points = points;
  options.seed = seed;
  options.progress = false;
  return generateScene(scene, options);
}

TEST(SceneNames, RoundTripAndHelpfulError) {
  for (Scene s : {Scene::Terrain, Scene::Tls}) {
    EXPECT_EQ(parseScene(sceneName(s)), s);
    EXPECT_TRUE(isSceneName(sceneName(s)));
  }
  EXPECT_FALSE(isSceneName("forest"));
  EXPECT_FALSE(isSceneName(""));
  try {
    parseScene("forest");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("terrain"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("tls"), std::string::npos);
  }
}

TEST(GenerateScene, RefusesCountsThatCannotBeHeld) {
  EXPECT_THROW(generate(Scene::Terrain, (uint64_t(1) << 40) + 1), InputError);
  EXPECT_THROW(generate(Scene::Tls, ~uint64_t(0)), InputError);
  // 2^39 points need 8 TiB: more than the memory of any machine running these tests.
  EXPECT_THROW(generate(Scene::Terrain, uint64_t(1) << 39), InputError);
}

class EachScene : public ::testing::TestWithParam<Scene> {};

TEST_P(EachScene, ExactCountBoundsAndSource) {
  for (uint64_t n : {uint64_t(0), uint64_t(1), uint64_t(2), uint64_t(1000), uint64_t(123457)}) {
    PointCloud cloud = generate(GetParam(), n);
    ASSERT_EQ(cloud.size(), n);
    ASSERT_EQ(cloud.positions.size(), 3 * n);
    ASSERT_EQ(cloud.colors.size(), n); // 16 B per point: nothing else allocated
    EXPECT_TRUE(cloud.intensity.empty());
    EXPECT_EQ(cloud.source,
              std::string(sceneName(GetParam())) + ", " + std::to_string(n) + " points, seed 1");
    EXPECT_EQ(cloud.scale, glm::dvec3(0.001));
    if (n == 0) {
      EXPECT_TRUE(cloud.bounds.empty());
      continue;
    }
    // Bounds are exact, and the coordinates look like a UTM survey at a plausible elevation.
    Bounds ref;
    for (uint64_t i = 0; i < n; ++i)
      ref.expand(cloud.world(i));
    EXPECT_EQ(cloud.bounds.min, ref.min);
    EXPECT_EQ(cloud.bounds.max, ref.max);
    EXPECT_GT(cloud.bounds.min.x, 499000.0);
    EXPECT_LT(cloud.bounds.max.x, 502000.0);
    EXPECT_GT(cloud.bounds.min.y, 3999000.0);
    EXPECT_LT(cloud.bounds.max.y, 4002000.0);
    EXPECT_GT(cloud.bounds.min.z, 100.0);
    EXPECT_LT(cloud.bounds.max.z, 300.0);
    if (n >= 1000) {
      EXPECT_GT(cloud.bounds.size().x, 20.0);
      EXPECT_GT(cloud.bounds.size().y, 20.0);
      EXPECT_GT(cloud.bounds.size().z, 1.0);
    }
  }
}

TEST_P(EachScene, DeterministicPerSeedDifferentAcrossSeeds) {
  PointCloud a = generate(GetParam(), 30'000, 7), b = generate(GetParam(), 30'000, 7);
  PointCloud c = generate(GetParam(), 30'000, 8);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.colors, b.colors);
  EXPECT_NE(a.positions, c.positions);
  EXPECT_NE(a.colors, c.colors);
}

TEST_P(EachScene, EveryPointIsAFunctionOfItsIndexAlone) {
  // Whatever the thread count, generateScene cuts the work into ranges; any range computed alone, in
  // one thread, must give the same points. Ranges chosen to straddle the 65536-point blocks.
  const uint64_t n = 200'000;
  PointCloud cloud = generate(GetParam(), n, 3);
  auto scene = detail::makeScene(GetParam(), n, 3);
  EXPECT_EQ(scene->offset, cloud.offset);
  const std::pair<uint64_t, uint64_t> ranges[] = {
      {0, 1}, {65535, 3}, {131000, 1100}, {12345, 1}, {n - 777, 777}};
  for (auto [first, count] : ranges) {
    std::vector<int32_t> positions(3 * count);
    std::vector<uint32_t> colors(count);
    scene->generate(first, count, positions.data(), colors.data(), nullptr);
    for (uint64_t k = 0; k < count; ++k) {
      ASSERT_EQ(colors[k], cloud.colors[first + k]) << "point " << first + k;
      for (int a = 0; a < 3; ++a)
        ASSERT_EQ(positions[3 * k + a], cloud.positions[3 * (first + k) + a]);
    }
  }
  // And the whole cloud in a single serial call.
  std::vector<int32_t> positions(3 * n);
  std::vector<uint32_t> colors(n);
  scene->generate(0, n, positions.data(), colors.data(), nullptr);
  EXPECT_EQ(positions, cloud.positions);
  EXPECT_EQ(colors, cloud.colors);
}

TEST_P(EachScene, ColorsAreOpaqueVariedAndRarelyBlack) {
  PointCloud cloud = generate(GetParam(), 100'000);
  uint64_t dark = 0;
  std::map<uint32_t, int> distinct;
  for (uint32_t c : cloud.colors) {
    ASSERT_EQ(c >> 24, 255u);
    const uint32_t r = c & 255, g = (c >> 8) & 255, b = (c >> 16) & 255;
    dark += r + g + b < 40;
    if (distinct.size() < 1000) distinct[c]++;
  }
  EXPECT_LT(dark, cloud.size() / 100);
  EXPECT_GE(distinct.size(), 1000u);
  EXPECT_TRUE(hasUsableColor(cloud));
}

TEST_P(EachScene, ScanOrderIsLocallyCoherentButNotMorton) {
  // Consecutive points of a scan are close (a scan line); the order is not already a Morton order.
  PointCloud cloud = generate(GetParam(), 100'000);
  std::vector<double> step;
  for (uint64_t i = 1; i < cloud.size(); ++i)
    step.push_back(glm::length(cloud.world(i) - cloud.world(i - 1)));
  std::nth_element(step.begin(), step.begin() + step.size() / 2, step.end());
  EXPECT_LT(step[step.size() / 2], 1.0);
  std::vector<uint64_t> morton;
  computeOrder(morton, cloud, Order::Morton, 1);
  uint64_t inPlace = 0;
  for (uint64_t i = 0; i < morton.size(); ++i)
    inPlace += morton[i] == i;
  EXPECT_LT(inPlace, cloud.size() / 10);
}

INSTANTIATE_TEST_SUITE_P(Scenes, EachScene, ::testing::Values(Scene::Terrain, Scene::Tls),
                         [](const auto& param) { return std::string(sceneName(param.param)); });

TEST(TerrainScene, HasBuildingsAndTreesAboveTheGround) {
  // Points well above the lowest point of their 5 m cell are roofs, walls or crowns.
  PointCloud cloud = generate(Scene::Terrain, 400'000);
  std::map<std::pair<int, int>, double> lowest;
  auto cell = [&](uint64_t i) {
    glm::dvec3 p = cloud.world(i) - cloud.bounds.min;
    return std::make_pair(int(p.x / 5), int(p.y / 5));
  };
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    auto [it, inserted] = lowest.try_emplace(cell(i), cloud.world(i).z);
    if (!inserted) it->second = std::min(it->second, cloud.world(i).z);
  }
  uint64_t raised = 0;
  for (uint64_t i = 0; i < cloud.size(); ++i)
    raised += cloud.world(i).z > lowest[cell(i)] + 2.5;
  EXPECT_GT(raised, cloud.size() / 50);
  EXPECT_LT(raised, cloud.size() / 2);
}

TEST(TerrainScene, AreaGrowsWithCountAtSurveyDensity) {
  // ~20 pulses per square metre: a million points cover roughly 220 m x 220 m.
  PointCloud cloud = generate(Scene::Terrain, 1'000'000);
  const glm::dvec3 size = cloud.bounds.size();
  EXPECT_NEAR(size.x, 224.0, 30.0);
  EXPECT_NEAR(size.y, 224.0, 30.0);
}

TEST(TlsScene, DensityFallsWithDistance) {
  // Count points per area in rings around the cloud's densest spot (a scanner station).
  PointCloud cloud = generate(Scene::Tls, 200'000);
  std::map<std::pair<int, int>, int> grid;
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    glm::dvec3 p = cloud.world(i);
    grid[{int(std::floor(p.x)), int(std::floor(p.y))}]++;
  }
  auto densest =
      std::max_element(grid.begin(), grid.end(), [](auto& a, auto& b) { return a.second < b.second; });
  const double cx = densest->first.first + 0.5, cy = densest->first.second + 0.5;
  auto ringDensity = [&](double r0, double r1) {
    uint64_t count = 0;
    for (uint64_t i = 0; i < cloud.size(); ++i) {
      glm::dvec3 p = cloud.world(i);
      double d = std::hypot(p.x - cx, p.y - cy);
      count += d >= r0 && d < r1;
    }
    return double(count) / (M_PI * (r1 * r1 - r0 * r0));
  };
  EXPECT_GT(ringDensity(2, 4), 4 * ringDensity(40, 60));
}

TEST(GenerateClassification, TerrainClassesFollowWhatEachPulseHit) {
  const uint64_t n = 300'000;
  GenerateOptions options;
  options.points = n;
  options.progress = false;
  const PointCloud plain = generateScene(Scene::Terrain, options);
  options.classification = true;
  const PointCloud classified = generateScene(Scene::Terrain, options);
  // The same points and colors; the classes besides.
  EXPECT_TRUE(plain.classification.empty());
  EXPECT_EQ(classified.positions, plain.positions);
  EXPECT_EQ(classified.colors, plain.colors);
  ASSERT_EQ(classified.classification.size(), n);
  uint64_t count[256] = {};
  for (uint8_t c : classified.classification)
    ++count[c];
  EXPECT_EQ(count[2] + count[5] + count[6], n) << "only ground, high vegetation and building";
  EXPECT_GT(count[2], n / 2) << "mostly ground";
  EXPECT_GT(count[5], n / 100);
  EXPECT_GT(count[6], n / 100);
  // Buildings stand above the ground around them: their mean height is above the ground's.
  double z[256] = {};
  for (uint64_t i = 0; i < n; ++i)
    z[classified.classification[i]] += classified.world(i).z;
  EXPECT_GT(z[6] / double(count[6]), z[2] / double(count[2]));
  // A share of the scene (a rank's) has the classes of the same points of the whole.
  options.first = 123'456;
  options.count = 5'000;
  const PointCloud share = generateScene(Scene::Terrain, options);
  for (uint64_t k = 0; k < options.count; ++k)
    ASSERT_EQ(share.classification[k], classified.classification[options.first + k]);
}

} // namespace
} // namespace pointrast

// GPU methods against the image contract (hand-built cases with known pixels) and against the CPU
// reference renderer (double precision) on random, generated and real clouds.
#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <random>

#include "base/error.h"
#include "cloud/generate.h"
#include "gpu_fixture.h"
#include "io/reader.h"
#include "oracles/cpu_reference.h"
#include "render/renderer.h"
#include "test_data.h"

namespace pointrast::test {

namespace {

std::vector<uint64_t> renderWords(gpu::Context& context, const PointCloud& cloud, const Camera& camera,
                                  uint32_t w, uint32_t h, const UploadOptions& upload = {}) {
  GpuScene scene(context, cloud, upload);
  Renderer renderer(context, w, h);
  RenderSettings settings;
  settings.captureWords = true;
  renderer.render(scene, camera, settings);
  return renderer.framebufferWords();
}

double equalFraction(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  size_t same = 0;
  for (size_t i = 0; i < a.size(); ++i)
    same += a[i] == b[i];
  return double(same) / double(a.size());
}

// Fraction of equal pixels among those lit in either image (a stricter figure than over all pixels).
double equalLitFraction(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b, uint32_t background) {
  size_t same = 0, lit = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] == background && b[i] == background) continue;
    ++lit;
    same += a[i] == b[i];
  }
  return lit ? double(same) / double(lit) : 1.0;
}

constexpr uint32_t kRed = 0xFF0000FFu, kGreen = 0xFF00FF00u, kBlue = 0xFFFF0000u;

} // namespace

TEST_F(GpuTest, ContractPixelPlacementAndDepthOrder) {
  // 4x4 image, aspect 1. Points: red at pixel (2,1) depth 1; green behind red on the same pixel; blue at
  // pixel (0,3); one behind the eye; one outside the image; one between eye and near plane.
  PointCloud cloud = cloudFromPoints(
      {{0.25, 0.25, -1}, {0.5, 0.5, -2}, {-0.9, -0.9, -1}, {0, 0, 1}, {3, 0, -1}, {0, 0, -0.005}},
      {kRed, kGreen, kBlue, kGreen, kGreen, kGreen});
  std::vector<uint64_t> words = renderWords(*context, cloud, axisCamera(), 4, 4);
  for (uint32_t i = 0; i < 16; ++i) {
    uint32_t x = i % 4, y = i / 4;
    if (x == 2 && y == 1) {
      EXPECT_EQ(uint32_t(words[i]), kRed);
      EXPECT_NEAR(std::bit_cast<float>(uint32_t(words[i] >> 32)), 1.0f, 1e-5f);
    } else if (x == 0 && y == 3) {
      EXPECT_EQ(uint32_t(words[i]), kBlue);
    } else {
      EXPECT_EQ(words[i], ~0ull) << "pixel " << x << "," << y << " should be empty";
    }
  }
}

TEST_F(GpuTest, ClosestPointWinsWhateverTheOrder) {
  // 1000 points on one pixel at distinct depths, in shuffled order: the nearest one's color must win.
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  std::mt19937 rng(7);
  std::vector<int> depths(1000);
  std::iota(depths.begin(), depths.end(), 0);
  std::shuffle(depths.begin(), depths.end(), rng);
  for (int d : depths) {
    points.push_back({0.01, 0.01, -(1.0 + d * 0.01)});
    colors.push_back(0xFF000000u | uint32_t(d + 1));
  }
  std::vector<uint64_t> words = renderWords(*context, cloudFromPoints(points, colors), axisCamera(), 8, 8);
  uint32_t pixel = 3 * 8 + 4; // px = floor((0.01 + 1)/2*8) = 4, py = floor((1 - 0.01)/2*8) = 3
  EXPECT_EQ(uint32_t(words[pixel]), 0xFF000001u);
}

TEST_F(GpuTest, RandomCloudMatchesCpuReference) {
  std::mt19937_64 rng(42);
  PointCloud cloud = randomBoxCloud(rng, 200'000, {50, 30, 10});
  uint32_t w = 320, h = 200;
  std::vector<Camera> cameras = {overviewCamera(cloud.bounds, double(w) / h)};
  Camera inside;
  inside.eye = {0, 0, 0};
  inside.target = {10, 3, -1};
  cameras.push_back(inside);
  for (const Camera& camera : cameras) {
    std::vector<uint32_t> gpu = resolveWords(renderWords(*context, cloud, camera, w, h), 0);
    std::vector<uint32_t> cpu = resolveWords(referenceFramebuffer(cloud, camera, w, h), 0);
    EXPECT_GE(equalFraction(gpu, cpu), 0.999) << describeCamera(camera);
    EXPECT_GE(equalLitFraction(gpu, cpu, 0), 0.995) << describeCamera(camera);
  }
}

TEST_F(GpuTest, GeneratedTerrainMatchesCpuReference) {
  GenerateOptions options;
  options.points = 300'000;
  options.progress = false;
  PointCloud cloud = generateScene(Scene::Terrain, options);
  uint32_t w = 640, h = 360;
  Camera camera = overviewCamera(cloud.bounds, double(w) / h);
  std::vector<uint32_t> gpu = resolveWords(renderWords(*context, cloud, camera, w, h), 0);
  std::vector<uint32_t> cpu = resolveWords(referenceFramebuffer(cloud, camera, w, h), 0);
  EXPECT_GE(equalFraction(gpu, cpu), 0.999);
  EXPECT_GE(equalLitFraction(gpu, cpu, 0), 0.99);
}

TEST_F(GpuTest, AutzenMatchesCpuReference) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  std::filesystem::path file = dataDir() / "las/autzen_trim.las";
  ASSERT_TRUE(std::filesystem::exists(file)) << file << " is missing (../shared/data)";
  io::ReadOptions read;
  read.progress = false;
  PointCloud cloud = io::readCloud(file, read);
  ASSERT_EQ(cloud.size(), 110000u);
  uint32_t w = 800, h = 450;
  Camera camera = overviewCamera(cloud.bounds, double(w) / h);
  std::vector<uint32_t> gpu = resolveWords(renderWords(*context, cloud, camera, w, h), 0);
  std::vector<uint32_t> cpu = resolveWords(referenceFramebuffer(cloud, camera, w, h), 0);
  EXPECT_GE(equalFraction(gpu, cpu), 0.999);
  EXPECT_GE(equalLitFraction(gpu, cpu, 0), 0.99);
}

TEST_F(GpuTest, PartsAndSeparateScenesGiveIdenticalFramebuffers) {
  std::mt19937_64 rng(3);
  PointCloud cloud = randomBoxCloud(rng, 100'000, {5, 5, 5});
  Camera camera = overviewCamera(cloud.bounds, 2.0);
  std::vector<uint64_t> whole = renderWords(*context, cloud, camera, 256, 128);

  UploadOptions small;
  small.maxPartPoints = 10240; // 10 parts, the last one short
  small.progress = false;
  EXPECT_EQ(renderWords(*context, cloud, camera, 256, 128, small), whole);

  // Three separately uploaded scenes of uneven size drawn into one framebuffer.
  std::vector<std::unique_ptr<GpuScene>> scenes;
  uint64_t cuts[] = {0, 33'333, 70'001, cloud.size()};
  for (int s = 0; s < 3; ++s) {
    UploadOptions o;
    o.first = cuts[s];
    o.count = cuts[s + 1] - cuts[s];
    o.progress = false;
    scenes.push_back(std::make_unique<GpuScene>(*context, cloud, o));
  }
  const GpuScene* drawn[] = {scenes[0].get(), scenes[1].get(), scenes[2].get()};
  Renderer renderer(*context, 256, 128);
  RenderSettings settings;
  settings.captureWords = true;
  renderer.render(drawn, camera, settings);
  EXPECT_EQ(renderer.framebufferWords(), whole);
}

TEST_F(GpuTest, TwoDimensionalGridReachesEveryPoint) {
  // 65535 * 128 + 1 points need a second row of workgroups; the very last point is the only red one
  // and the nearest, so it must win its pixel.
  uint64_t n = 65535ull * 128 + 1;
  PointCloud cloud;
  cloud.scale = glm::dvec3(1e-3);
  cloud.positions.assign(3 * n, 0);
  for (uint64_t i = 0; i < n; ++i)
    cloud.positions[3 * i + 2] = -2000;     // z = -2
  cloud.positions[3 * (n - 1) + 2] = -1000; // z = -1: closer
  cloud.colors.assign(n, kGreen);
  cloud.colors[n - 1] = kRed;
  computeBounds(cloud);
  Camera camera = axisCamera();
  UploadOptions upload;
  upload.progress = false;
  std::vector<uint64_t> words = renderWords(*context, cloud, camera, 2, 2, upload);
  // (0, 0) is the corner of four pixels: floor((0 + 1) / 2 * 2) = 1 on both axes.
  EXPECT_EQ(uint32_t(words[1 * 2 + 1]), kRed);
}

TEST_F(GpuTest, TimingsArePositiveAndOrdered) {
  PointCloud cloud = cloudFromPoints({{0, 0, -1}}, {kRed});
  GpuScene scene(*context, cloud);
  Renderer renderer(*context, 64, 64);
  RenderSettings settings;
  settings.frames = 5;
  FrameStats stats = renderer.render(scene, axisCamera(), settings);
  EXPECT_EQ(stats.frames, 5u);
  EXPECT_GT(stats.medianMs, 0.0);
  EXPECT_LE(stats.minMs, stats.medianMs);
  EXPECT_LE(stats.medianMs, stats.maxMs);
}

TEST_F(GpuTest, BadImageSizeIsAnInputError) {
  EXPECT_THROW(Renderer(*context, 0, 10), InputError);
  EXPECT_THROW(Renderer(*context, 100000, 10), InputError);
}

} // namespace pointrast::test

// The 2019/2021 method family against each other and against independent CPU computations:
// - every closest-point method writes bit-identical framebuffer words (clouds x orders x views);
// - justset lights exactly the pixels atomicmin lights;
// - hqs equals a CPU average within 1 per channel; hqs1r equals hqs, also past 1,000 points per pixel;
// - int40 depth separates surfaces 1 mm apart at 10 km that float depth merges.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>

#include "base/error.h"
#include "cloud/generate.h"
#include "cloud/order.h"
#include "gpu_fixture.h"
#include "render/renderer.h"

namespace pointrast::test {

namespace {

struct Result {
  std::vector<uint64_t> words;
  std::vector<uint32_t> image;
};

Result draw(gpu::Context& context, const GpuScene& scene, const Camera& camera, uint32_t w, uint32_t h,
            Method method, DepthMode depth = DepthMode::Float) {
  Renderer renderer(context, w, h);
  RenderSettings settings;
  settings.method = method;
  settings.depth = depth;
  settings.captureWords = true;
  settings.background = 0;
  renderer.render(scene, camera, settings);
  bool blends = method == pointMethod("hqs") || method == pointMethod("hqs1r");
  return {blends ? std::vector<uint64_t>{} : renderer.framebufferWords(), renderer.image()};
}

// Three clouds that stress different paths: a random box (few points per pixel), generated terrain (a
// real-looking surface) and a dense blob where whole subgroups hit one pixel (reduce's fast path, and
// contention for busyloop's lock).
std::map<std::string, PointCloud> testClouds() {
  std::map<std::string, PointCloud> clouds;
  std::mt19937_64 rng(11);
  clouds["box"] = randomBoxCloud(rng, 60'000, {20, 10, 5});
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  for (int i = 0; i < 60'000; ++i) {
    points.push_back({u(rng) * 0.05, u(rng) * 0.05, u(rng) * 0.05});
    colors.push_back(0xFF000000u | uint32_t(rng() & 0xFF)); // few colors: many equal depths break by color
  }
  points.push_back({5, 5, 5}); // stretch the bounds so the blob is a few pixels in the overview
  colors.push_back(0xFFFFFFFFu);
  clouds["blob"] = cloudFromPoints(points, colors);
  GenerateOptions options;
  options.points = 80'000;
  options.progress = false;
  clouds["terrain"] = generateScene(Scene::Terrain, options);
  return clouds;
}

std::vector<std::pair<std::string, Camera>> views(const Bounds& bounds, double aspect) {
  Camera inside;
  inside.eye = bounds.center() + 0.1 * (bounds.max - bounds.center());
  inside.target = bounds.max;
  return {{"overview", overviewCamera(bounds, aspect)}, {"inside", inside}};
}

} // namespace

namespace {

// Every row of the method table that must write atomicmin's words bit for bit: the closest-point rows of
// the float layout (the batch rows quantize: batch_test.cpp). A row added to the table is tested here
// without any change to this file.
std::vector<Method> closestFloatMethods() {
  std::vector<Method> methods;
  for (Method m : allMethods())
    if (m != pointMethod("atomicmin") && m.info().output == MethodOutput::Closest &&
        m.info().layout == SceneLayout::Float)
      methods.push_back(m);
  return methods;
}

// atomicmin's result per cloud, order and view, drawn once for all the rows compared with it.
const Result& referenceFor(gpu::Context& context, const std::string& where, const GpuScene& scene,
                           const Camera& camera, uint32_t w, uint32_t h, DepthMode depth = DepthMode::Float) {
  static std::map<std::string, Result> references;
  const std::string key = where + (depth == DepthMode::Int40 ? " / int40" : "");
  auto found = references.find(key);
  if (found == references.end())
    found =
        references.emplace(key, draw(context, scene, camera, w, h, pointMethod("atomicmin"), depth)).first;
  return found->second;
}

constexpr uint32_t kWidth = 160, kHeight = 100;

// Calls check(where, scene, camera, reference) for every test cloud, vertex order and view, with
// atomicmin's result as the reference (which lights some pixels in every case).
template <class Check> void forEachCase(gpu::Context& context, Check&& check) {
  for (auto& [cloudName, original] : testClouds()) {
    for (Order order : {Order::Original, Order::Morton, Order::Shuffled, Order::ShuffledMorton}) {
      PointCloud cloud = original;
      reorder(cloud, order, 5);
      UploadOptions upload;
      upload.progress = false;
      GpuScene scene(context, cloud, upload);
      for (auto& [viewName, camera] : views(cloud.bounds, double(kWidth) / kHeight)) {
        const std::string where = cloudName + " / " + orderName(order) + " / " + viewName;
        const Result& reference = referenceFor(context, where, scene, camera, kWidth, kHeight);
        EXPECT_GT(std::count_if(reference.words.begin(), reference.words.end(),
                                [](uint64_t v) { return v != ~0ull; }),
                  0)
            << where;
        check(where, scene, camera, reference);
      }
    }
  }
}

// The terrain test cloud uploaded, and its overview camera in `camera`.
std::unique_ptr<GpuScene> terrainScene(gpu::Context& context, Camera& camera) {
  auto clouds = testClouds();
  const PointCloud& cloud = clouds.at("terrain");
  UploadOptions upload;
  upload.progress = false;
  camera = overviewCamera(cloud.bounds, 1.6);
  return std::make_unique<GpuScene>(context, cloud, upload);
}

class ClosestMethodTest : public GpuTest, public ::testing::WithParamInterface<Method> {
protected:
  void SetUp() override {
    GpuTest::SetUp();
    if (!context) return;
    std::string why;
    if (!Renderer::supports(*context, GetParam(), &why)) GTEST_SKIP() << why;
  }
};

std::string paramName(const ::testing::TestParamInfo<Method>& info) {
  std::string name = info.param.name();
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

} // namespace

// busyloop runs with its release ordering on GPUs and without it on CPU devices (see its shader), so this
// covers the variant each kind of device uses.
TEST_P(ClosestMethodTest, WritesAtomicMinsWordsBitForBit) {
  const Method method = GetParam();
  forEachCase(*context, [&](const std::string& where, const GpuScene& scene, const Camera& camera,
                            const Result& reference) {
    Result r = draw(*context, scene, camera, kWidth, kHeight, method);
    EXPECT_EQ(r.words, reference.words) << methodName(method) << " differs from atomicmin on " << where;
    EXPECT_EQ(r.image, reference.image) << methodName(method) << " image differs on " << where;
  });
}

TEST_P(ClosestMethodTest, Int40AgreesWithAtomicMin) {
  const Method method = GetParam();
  if (!method.info().int40Shader) GTEST_SKIP() << methodName(method) << " has no int40 encoding";
  if (!context->features().float64) GTEST_SKIP() << "no shaderFloat64 on this device";
  Camera camera;
  const std::unique_ptr<GpuScene> terrain = terrainScene(*context, camera);
  const GpuScene& scene = *terrain;
  const Result& reference =
      referenceFor(*context, "terrain int40", scene, camera, 160, 100, DepthMode::Int40);
  EXPECT_EQ(draw(*context, scene, camera, 160, 100, method, DepthMode::Int40).words, reference.words)
      << methodName(method);
}

INSTANTIATE_TEST_SUITE_P(Table, ClosestMethodTest, ::testing::ValuesIn(closestFloatMethods()), paramName);

TEST_F(GpuTest, JustSetLightsThePixelsAtomicMinLights) {
  forEachCase(*context, [&](const std::string& where, const GpuScene& scene, const Camera& camera,
                            const Result& reference) {
    Result set = draw(*context, scene, camera, kWidth, kHeight, pointMethod("justset"));
    for (size_t i = 0; i < set.words.size(); ++i)
      ASSERT_EQ(set.words[i] == ~0ull, reference.words[i] == ~0ull)
          << "justset lit pixels differ on " << where;
  });
}

TEST_F(GpuTest, Int40LightsThePixelsFloatDepthLights) {
  Camera camera;
  const std::unique_ptr<GpuScene> terrain = terrainScene(*context, camera);
  const GpuScene& scene = *terrain;
  Result reference = draw(*context, scene, camera, 160, 100, pointMethod("atomicmin"), DepthMode::Int40);
  // Same pixels lit as with float depth; colors are RGB with alpha restored.
  Result floatDepth = draw(*context, scene, camera, 160, 100, pointMethod("atomicmin"));
  size_t samePixels = 0;
  for (size_t i = 0; i < reference.words.size(); ++i)
    samePixels += (reference.words[i] == ~0ull) == (floatDepth.words[i] == ~0ull);
  EXPECT_GE(samePixels, reference.words.size() * 999 / 1000);
}

namespace {

// Fraction of lit pixels showing the back surface of two 128 x 128 grids of points (jittered on an 8 mm
// pitch), the back one `gap` below the front one, seen from `distance` almost straight above through a
// telephoto lens so each pixel holds one point of each. Back points get the smaller color, so a depth tie
// shows the back surface.
double backSurfaceFraction(gpu::Context& context, double gap, double distance, DepthMode mode) {
  constexpr uint32_t kBack = 0xFF0000FFu, kFront = 0xFF00FF00u;
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> jitter(0.25, 0.75);
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) {
      glm::dvec3 p{(x + jitter(rng)) * 0.008, (y + jitter(rng)) * 0.008, 0.0};
      points.push_back(p);
      colors.push_back(kFront);
      points.push_back(p - glm::dvec3(0, 0, gap));
      colors.push_back(kBack);
    }
  PointCloud cloud = cloudFromPoints(points, colors, 1e-6);
  Camera camera;
  camera.target = {0.512, 0.512, 0.0};
  camera.eye = camera.target + distance * glm::normalize(glm::dvec3(3.0, 4.0, 9999.0)); // not axis-aligned
  camera.up = {0, 1, 0};
  camera.fovY = glm::degrees(2 * std::atan(0.512 / distance));
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(context, cloud, upload);
  Result r = draw(context, scene, camera, 128, 128, pointMethod("atomicmin"), mode);
  size_t back = 0, lit = 0;
  for (uint32_t c : r.image) {
    lit += c != 0;
    back += (c & 0xFFFFFFu) == (kBack & 0xFFFFFFu);
  }
  EXPECT_GT(lit, 128u * 128u / 2);
  return double(back) / double(lit);
}

} // namespace

TEST_F(GpuTest, Int40SeparatesSurfacesOneMillimetreApartAtTenKilometres) {
  // int40 depth (projection in double, 40-bit steps over the scene's depth range: 9 nm at 10 km) keeps
  // the front surface everywhere.
  EXPECT_EQ(backSurfaceFraction(*context, 0.001, 10'000.0, DepthMode::Int40), 0.0);
  // Float depth has a 0.98 mm step at 10 km (2^-10 between 8192 and 16384). With origin-relative positions
  // and a matrix built in double its error stays below half a step, so it still separates 1 mm here;
  // below its step it merges the surfaces, which int40 keeps apart.
  double float1mm = backSurfaceFraction(*context, 0.001, 10'000.0, DepthMode::Float);
  double floatHalf = backSurfaceFraction(*context, 0.0005, 10'000.0, DepthMode::Float);
  double int40Half = backSurfaceFraction(*context, 0.0005, 10'000.0, DepthMode::Int40);
  std::printf(
      "back surface visible at 10 km: 1 mm gap: float %.1f %%; 0.5 mm gap: float %.1f %%, int40 %.1f %%\n",
      100 * float1mm, 100 * floatHalf, 100 * int40Half);
  EXPECT_GT(floatHalf, 0.10) << "float depth was expected to merge surfaces closer than its step";
  EXPECT_EQ(int40Half, 0.0);
}

namespace {

// An independent HQS on the CPU for clouds whose points sit near pixel centers (no pixel-border ties):
// closest float depth per pixel, then the rounded average of every point within 1 % of it.
// Points whose pixel is kDropped are outside the view and take no part.
constexpr uint32_t kDropped = UINT32_MAX;

std::vector<uint32_t> cpuHqs(const std::vector<glm::dvec3>& viewPoints, const std::vector<uint32_t>& colors,
                             const std::vector<uint32_t>& pixels, size_t n) {
  std::vector<float> closest(n, INFINITY);
  for (size_t i = 0; i < viewPoints.size(); ++i)
    if (pixels[i] != kDropped) closest[pixels[i]] = std::min(closest[pixels[i]], float(viewPoints[i].z));
  std::vector<uint64_t> sum(n * 4, 0);
  for (size_t i = 0; i < viewPoints.size(); ++i) {
    uint32_t p = pixels[i];
    if (p == kDropped || float(viewPoints[i].z) > closest[p] * 1.01f) continue;
    for (int c = 0; c < 3; ++c)
      sum[4 * p + c] += (colors[i] >> (8 * c)) & 0xFF;
    sum[4 * p + 3] += 1;
  }
  std::vector<uint32_t> image(n, 0);
  for (size_t p = 0; p < n; ++p) {
    uint64_t k = sum[4 * p + 3];
    if (!k) continue;
    uint32_t rgb = 0;
    for (int c = 0; c < 3; ++c)
      rgb |= uint32_t((sum[4 * p + c] + k / 2) / k) << (8 * c);
    image[p] = rgb | 0xFF000000u;
  }
  return image;
}

} // namespace

TEST_F(GpuTest, HqsMatchesCpuAverageAndHqs1rMatchesHqs) {
  // Camera at the origin looking down -z, 90 degrees, 64 x 64: pixel (x, y) has its center at view
  // direction ((x + 0.5) / 32 - 1, 1 - (y + 0.5) / 32, -1). Points are put near pixel centers at depths
  // that are either well within 1 % of the pixel's front surface or 3 % behind it.
  constexpr uint32_t W = 64, H = 64;
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), layer(0.0, 0.004);
  std::vector<glm::dvec3> points, view;
  std::vector<uint32_t> colors, pixels;
  auto add = [&](uint32_t px, uint32_t py, double depth, uint32_t color) {
    double sx = (px + 0.5 + jitter(rng)) / (W / 2.0) - 1.0, sy = 1.0 - (py + 0.5 + jitter(rng)) / (H / 2.0);
    points.push_back({sx * depth, sy * depth, -depth});
    view.push_back({0, 0, depth});
    colors.push_back(color);
    pixels.push_back(py * W + px);
  };
  for (uint32_t py = 0; py < H; ++py)
    for (uint32_t px = 0; px < W; ++px) {
      if ((px * 7 + py * 3) % 11 == 0) continue; // some empty pixels
      double front = 2.0 + 0.5 * std::sin(px * 0.2) + 0.3 * std::cos(py * 0.3);
      int count = 1 + int(rng() % 6);
      for (int k = 0; k < count; ++k)
        add(px, py, front * (1.0 + layer(rng)), 0xFF000000u | uint32_t(rng() & 0xFFFFFF));
      add(px, py, front * 1.03, 0xFF0000FFu); // hidden: beyond 1 %
      // A point the projection drops, between drawn ones (so in their subgroups): behind the eye, or
      // beside the frustum. It must not blend anywhere.
      points.push_back(px % 2 ? glm::dvec3(0.1, 0.1, 1.0) : glm::dvec3(-50.0, 0.0, -1.0));
      view.push_back({0, 0, 1});
      colors.push_back(0xFFFFFFFFu);
      pixels.push_back(kDropped);
    }
  // One pixel with 1,500 blended points: past hqs1r's 255-point packed word.
  for (int k = 0; k < 1500; ++k)
    add(10, 20, 1.5 * (1.0 + layer(rng)), 0xFF000000u | uint32_t(rng() & 0xFFFFFF));

  PointCloud cloud = cloudFromPoints(points, colors, 1e-7);
  // The quantized positions move points by < 1e-7: recompute the CPU view depths from them.
  for (size_t i = 0; i < view.size(); ++i)
    if (pixels[i] != kDropped) view[i].z = -cloud.world(i).z;
  Camera camera;
  camera.eye = {0, 0, 0};
  camera.target = {0, 0, -1};
  camera.up = {0, 1, 0};
  camera.fovY = 90;
  camera.nearW = 0.01;
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(*context, cloud, upload);
  std::vector<uint32_t> cpu = cpuHqs(view, colors, pixels, W * H);
  std::vector<uint32_t> hqs = draw(*context, scene, camera, W, H, pointMethod("hqs")).image;
  std::vector<uint32_t> hqs1r = draw(*context, scene, camera, W, H, pointMethod("hqs1r")).image;
  auto maxChannelDiff = [](const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
    int worst = 0;
    for (size_t i = 0; i < a.size(); ++i)
      for (int c = 0; c < 4; ++c)
        worst = std::max(worst, std::abs(int((a[i] >> (8 * c)) & 0xFF) - int((b[i] >> (8 * c)) & 0xFF)));
    return worst;
  };
  EXPECT_LE(maxChannelDiff(hqs, cpu), 1);
  EXPECT_LE(maxChannelDiff(hqs1r, hqs), 1);
  EXPECT_NE(hqs[20 * W + 10], 0u);
  EXPECT_LE(maxChannelDiff({hqs1r[20 * W + 10]}, {cpu[20 * W + 10]}), 1);
}

TEST_F(GpuTest, UnsupportedCombinationsAreClearErrors) {
  PointCloud cloud = cloudFromPoints({{0, 0, -1}}, {0xFFFFFFFFu});
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(*context, cloud, upload);
  Renderer renderer(*context, 8, 8);
  RenderSettings settings;
  settings.method = pointMethod("hqs");
  settings.depth = DepthMode::Int40;
  EXPECT_THROW(renderer.render(scene, overviewCamera(cloud.bounds, 1.0), settings), InputError);
  if (!Renderer::supports(*context, pointMethod("dedup"))) {
    settings.method = pointMethod("dedup");
    settings.depth = DepthMode::Float;
    EXPECT_THROW(renderer.render(scene, overviewCamera(cloud.bounds, 1.0), settings), UnsupportedError);
  }
}

} // namespace pointrast::test

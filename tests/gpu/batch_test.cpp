// The 2022 batch methods (batch, batch-prefetch, batch-hqs) and their scene layout:
// - the upload writes exactly what cloud/batch_words.h encodes, bounds and colors included;
// - at full precision (3 words) batch and batch-prefetch match atomicmin on >= 99.9 % of lit pixels (clouds x
//   orders x views, one of them inside the cloud where the near plane cuts batches and most are culled);
// - adaptive precision keeps >= 99.5 % of the lit pixels and moves no point by more than one pixel, checked
//   per point through colors that encode the point's index;
// - frustum culling changes no framebuffer word (against culling switched off);
// - statistics are exact on a hand-built scene of known batches and known occlusion;
// - several parts and several scenes give the framebuffer of one part (the part number of visibility
//   indices), and more than 64 parts or a scene of the wrong layout is a clear error;
// - batch-hqs equals hqs within 1 per channel, and its one-pass drawing of dense batches gives the image of
//   two passes, also where pixels must be taken back;
// - the ways of reaching a batch's decision (a pass before the drawing, or one thread of the workgroup; the
//   first words loaded before or after it: the timing reference rows) write the same framebuffer words.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <tuple>

#include "base/error.h"
#include "cloud/batch_words.h"
#include "cloud/generate.h"
#include "cloud/order.h"
#include "gpu/buffer.h"
#include "gpu/shader_registry.h"
#include "gpu/shared_types.h"
#include "gpu/spirv_reflect.h"
#include "gpu_fixture.h"
#include "io/reader.h"
#include "render/renderer.h"
#include "test_data.h"

namespace pointrast::test {

namespace {

struct Drawn {
  std::vector<uint64_t> words; // canonical words (closest-point methods)
  std::vector<uint32_t> image;
  FrameStats stats;
};

struct Draw {
  Method method = pointMethod("batch");
  uint32_t precision = 0;
  bool culling = true;
  bool dense = true; // batch-hqs: dense batches in one pass
  uint32_t warmup = 1;
};

// One renderer per image size for the whole test binary (there is one context): a renderer keeps the
// pipelines of each method it has drawn, and on lavapipe making them costs far more than drawing these
// small scenes. Every frame starts from a cleared framebuffer and counts its own statistics.
// A test that counts what a first frame decides (batch-hqs's dense batches, decided from the frame before)
// forgets them first.
std::map<std::tuple<gpu::Context*, uint32_t, uint32_t>, std::unique_ptr<Renderer>>& renderers() {
  static std::map<std::tuple<gpu::Context*, uint32_t, uint32_t>, std::unique_ptr<Renderer>> kept;
  return kept;
}
void forgetRenderers() {
  renderers().clear();
}

Renderer& rendererFor(gpu::Context& context, uint32_t w, uint32_t h) {
  std::unique_ptr<Renderer>& r = renderers()[{&context, w, h}];
  if (!r) r = std::make_unique<Renderer>(context, w, h);
  return *r;
}

Drawn draw(gpu::Context& context, std::span<const GpuScene* const> scenes, const Camera& camera, uint32_t w,
           uint32_t h, const Draw& d) {
  Renderer& renderer = rendererFor(context, w, h);
  RenderSettings settings;
  settings.method = d.method;
  settings.precision = d.precision;
  settings.batchCulling = d.culling;
  settings.batchHqsDense = d.dense;
  settings.warmup = d.warmup;
  settings.captureWords = true;
  settings.background = 0;
  Drawn out;
  out.stats = renderer.render(scenes, camera, settings);
  if (methodInfo(d.method).output == MethodOutput::Closest) out.words = renderer.framebufferWords();
  out.image = renderer.image();
  return out;
}
Drawn draw(gpu::Context& context, const GpuScene& scene, const Camera& camera, uint32_t w, uint32_t h,
           const Draw& d) {
  const GpuScene* one[] = {&scene};
  return draw(context, one, camera, w, h, d);
}

UploadOptions batched(uint64_t maxPartPoints = 0) {
  UploadOptions o;
  o.layout = SceneLayout::Batched;
  o.maxPartPoints = maxPartPoints;
  o.progress = false;
  return o;
}
UploadOptions floats() {
  UploadOptions o;
  o.progress = false;
  return o;
}

size_t litCount(const std::vector<uint32_t>& image) {
  return size_t(std::count_if(image.begin(), image.end(), [](uint32_t c) { return c != 0; }));
}

// Fraction of equal pixels among those lit in either image.
double equalLitFraction(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  size_t same = 0, lit = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] == 0 && b[i] == 0) continue;
    ++lit;
    same += a[i] == b[i];
  }
  return lit ? double(same) / double(lit) : 1.0;
}

PointCloud autzen() {
  std::filesystem::path file = dataDir() / "las/autzen_trim.las";
  io::ReadOptions read;
  read.progress = false;
  return io::readCloud(file, read);
}

// A random box (few points per pixel), generated terrain and the real autzen_trim.las (110,000 points).
std::map<std::string, PointCloud> testClouds() {
  std::map<std::string, PointCloud> clouds;
  std::mt19937_64 rng(21);
  clouds["random"] = randomBoxCloud(rng, 100'000, {20, 10, 5});
  GenerateOptions options;
  options.points = 80'000;
  options.progress = false;
  clouds["terrain"] = generateScene(Scene::Terrain, options);
  clouds["autzen"] = autzen();
  return clouds;
}

// overview: the whole cloud; inside: from inside the bounds towards a corner; close: the eye at the center
// looking along +x, so that batches around the eye cross the near plane and most batches are culled.
std::vector<std::pair<std::string, Camera>> views(const Bounds& bounds, double aspect) {
  Camera inside;
  inside.eye = bounds.center() + 0.1 * (bounds.max - bounds.center());
  inside.target = bounds.max;
  Camera close;
  close.eye = bounds.center();
  close.target = bounds.center() + glm::dvec3(1, 0, 0);
  return {{"overview", overviewCamera(bounds, aspect)}, {"inside", inside}, {"close", close}};
}

// Colors 1..n in the low 24 bits: a pixel's color names its point.
void colorsAreIndices(PointCloud& cloud) {
  cloud.colors.resize(cloud.size());
  for (uint64_t i = 0; i < cloud.size(); ++i)
    cloud.colors[i] = 0xFF000000u | uint32_t(i + 1);
}

} // namespace

TEST(BatchLayout, ShadersMatchTheSharedStructs) {
  for (const char* name : {"raster_batch.comp", "raster_batch_hqs.comp"}) {
    gpu::SpirvReflection r = gpu::reflectSpirv(gpu::findShader(name));
    EXPECT_EQ(r.pushConstantSize, sizeof(shared::BatchPush)) << name;
    EXPECT_EQ(r.localSize[0] * r.localSize[1] * r.localSize[2], shared::kPointGroupSize) << name;
  }
  EXPECT_EQ(gpu::reflectSpirv(gpu::findShader("resolve_batch.comp")).pushConstantSize,
            sizeof(shared::ResolvePush));
}

TEST(BatchLayout, PartCapacityAndBytes) {
  constexpr uint64_t kBatch = shared::kBatchPoints;
  EXPECT_EQ(partCapacity(SceneLayout::Batched, 0, uint64_t(1) << 40), 6553 * kBatch);
  EXPECT_EQ(6553 * kBatch, 67'102'720u);
  EXPECT_LT(6553 * kBatch, uint64_t(1) << shared::kVisibilityPartShift);
  // A device whose largest buffer holds 1 MiB: 256 k words, 25 whole batches.
  EXPECT_EQ(partCapacity(SceneLayout::Batched, 0, 1 << 20), 25 * kBatch);
  EXPECT_EQ(partCapacity(SceneLayout::Batched, 2 * kBatch, uint64_t(1) << 40), 2 * kBatch);
  EXPECT_EQ(partCapacity(SceneLayout::Batched, 10000 * kBatch, uint64_t(1) << 40), 6553 * kBatch);
  EXPECT_EQ(partCapacity(SceneLayout::Batched, 0, kBatch * 4 - 1), 0u);
  EXPECT_EQ(partCapacity(SceneLayout::Float, 0, uint64_t(1) << 40), uint64_t(64) << 20);
  EXPECT_EQ(partCapacity(SceneLayout::Float, 12345, uint64_t(1) << 40), 12345u);
  EXPECT_EQ(sceneBytes(SceneLayout::Float, 1000), 16000u);
  EXPECT_EQ(sceneBytes(SceneLayout::Batched, 10241), 10241u * 16 + 2 * 32);
  // 4 billion points: 60 parts, under the 64 a frame addresses, and 4 words a point stay 16 B a point.
  uint64_t billions = uint64_t(4'000'000'000);
  EXPECT_LE((billions + 6553 * kBatch - 1) / (6553 * kBatch), uint64_t(shared::kMaxVisibilityParts));
  EXPECT_EQ(parsePrecision("adaptive"), 0u);
  EXPECT_EQ(parsePrecision("3"), 3u);
  EXPECT_THROW(parsePrecision("4"), InputError);
  EXPECT_THROW(parsePrecision("30"), InputError);
}

TEST_F(GpuTest, BatchedUploadWritesTheBatchWordsOfEveryBatch) {
  // 25,003 points in parts of 2 batches: parts of 20480 and 4523 points, the last batch 4523 points long
  // (not a multiple of 4: padding), uploaded from point 7 on so batches do not start at cloud multiples.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  for (int i = 0; i < 25'010; ++i) {
    points.push_back({1000 + u(rng) * 50, -200 + u(rng) * 3, u(rng) * 0.5});
    colors.push_back(0xFF000000u | uint32_t(rng() & 0xFFFFFF));
  }
  PointCloud cloud = cloudFromPoints(points, colors, 1e-3, {1000, 0, 0});
  UploadOptions upload = batched(2 * shared::kBatchPoints);
  upload.first = 7;
  upload.count = 25'003;
  GpuScene scene(*context, cloud, upload);
  EXPECT_EQ(scene.layout(), SceneLayout::Batched);
  EXPECT_EQ(scene.pointCount(), 25'003u);
  EXPECT_EQ(scene.bytes(), 25'003u * 16 + 3 * 32);
  ASSERT_EQ(scene.parts().size(), 2u);
  EXPECT_EQ(scene.parts()[0].count, 20480u);
  EXPECT_EQ(scene.parts()[1].count, 4523u);
  EXPECT_EQ(scene.parts()[1].first, 7u + 20480u);
  EXPECT_FALSE(scene.parts()[0].positions) << "the batched layout has no float positions";
  uint64_t checked = 0;
  for (const ScenePart& part : scene.parts()) {
    uint64_t padded = (part.count + 3) / 4 * 4;
    std::vector<uint32_t> words[3];
    const gpu::Buffer* buffers[3] = {&part.high, &part.medium, &part.low};
    for (int w = 0; w < 3; ++w) {
      ASSERT_EQ(buffers[w]->size(), padded * 4);
      words[w].resize(padded);
      gpu::readBuffer(*context, *buffers[w], 0, words[w].data(), padded * 4);
    }
    std::vector<uint32_t> gpuColors(part.count);
    gpu::readBuffer(*context, part.colors, 0, gpuColors.data(), part.count * 4);
    std::vector<shared::BatchBounds> bounds(part.batchCount());
    gpu::readBuffer(*context, part.batches, 0, bounds.data(), bounds.size() * sizeof(shared::BatchBounds));
    for (uint64_t b = 0; b < part.batchCount(); ++b) {
      uint64_t local = b * shared::kBatchPoints;
      Batch batch = makeBatch(cloud, part.first + local,
                              uint32_t(std::min<uint64_t>(shared::kBatchPoints, part.count - local)));
      std::vector<uint32_t> expect[3];
      for (auto& e : expect)
        e.resize(batch.count);
      encodeBatchWords(expect[0].data(), expect[1].data(), expect[2].data(), cloud, batch);
      for (int w = 0; w < 3; ++w)
        ASSERT_TRUE(std::equal(expect[w].begin(), expect[w].end(), words[w].begin() + local)) << "word " << w;
      glm::vec3 lo(batch.bounds.min - cloud.origin()), hi(batch.bounds.max - cloud.origin());
      EXPECT_EQ(glm::vec3(bounds[b].min), lo);
      EXPECT_EQ(glm::vec3(bounds[b].max), hi);
      for (uint32_t k = 0; k < batch.count; ++k)
        ASSERT_EQ(gpuColors[local + k], colors[batch.first + k]);
      checked += batch.count;
    }
    for (uint64_t k = part.count; k < padded; ++k)
      for (int w = 0; w < 3; ++w)
        EXPECT_EQ(words[w][k], 0u) << "padding word";
  }
  EXPECT_EQ(checked, 25'003u);
}

TEST_F(GpuTest, BatchAtFullPrecisionMatchesAtomicMin) {
  POINTRAST_REQUIRE_DATA();
  // Colors are point indices, so that both methods break depth ties alike (atomicmin by the smaller color,
  // batch by the smaller visibility index) and an equal pixel means the same point won: in dense views
  // many pixels hold two points of equal float depth.
  uint32_t w = 200, h = 120;
  for (auto& [cloudName, original] : testClouds()) {
    for (Order order : {Order::Original, Order::Morton, Order::Shuffled}) {
      PointCloud cloud = original;
      reorder(cloud, order, 3);
      colorsAreIndices(cloud);
      GpuScene floatScene(*context, cloud, floats());
      GpuScene batchScene(*context, cloud, batched());
      for (auto& [viewName, camera] : views(cloud.bounds, double(w) / h)) {
        std::string where = cloudName + " / " + orderName(order) + " / " + viewName;
        Drawn reference = draw(*context, floatScene, camera, w, h, {pointMethod("atomicmin")});
        EXPECT_GT(litCount(reference.image), 100u) << where;
        Drawn batch = draw(*context, batchScene, camera, w, h, {pointMethod("batch"), 3});
        Drawn prefetch = draw(*context, batchScene, camera, w, h, {pointMethod("batch-prefetch"), 3});
        double same = equalLitFraction(batch.image, reference.image);
        EXPECT_GE(same, 0.999) << where;
        if (same < 1.0) std::printf("%s: %.4f %% of lit pixels equal\n", where.c_str(), 100 * same);
        // Both decode every point the same way: the same words, bit for bit.
        EXPECT_EQ(prefetch.words, batch.words) << where;
        ASSERT_TRUE(batch.stats.batch && prefetch.stats.batch);
        const BatchStats& s = *batch.stats.batch;
        EXPECT_EQ(s.batchesProcessed, (cloud.size() + 10239) / 10240) << where;
        EXPECT_EQ(s.pointsByWords[0] + s.pointsByWords[1], 0u) << where << ": precision forced to 3 words";
        EXPECT_EQ(s.pointsProcessed, s.pointsByWords[2]);
        EXPECT_LE(s.pointsRendered, s.pointsProcessed);
        EXPECT_GE(s.pointsRendered, litCount(batch.image)) << where;
        EXPECT_EQ(prefetch.stats.batch->batchesRendered, s.batchesRendered) << where;
        EXPECT_EQ(prefetch.stats.batch->pointsProcessed, s.pointsProcessed) << where;
        if (viewName == "close" && order == Order::Morton) {
          EXPECT_LT(s.batchesRendered, s.batchesProcessed) << where << ": expected culled batches";
        }
      }
    }
  }
}

TEST_F(GpuTest, AdaptivePrecisionMovesNoPointByMoreThanOnePixel) {
  POINTRAST_REQUIRE_DATA();
  // Colors name points, so the pixel of every point visible in both images can be compared between
  // adaptive precision and the full 30 bits. A sparse random cloud (almost every point visible) and dense
  // ones (terrain, autzen: the points that win their pixel in both).
  std::map<std::string, PointCloud> clouds = testClouds();
  {
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<glm::dvec3> points;
    for (int i = 0; i < 400'000; ++i)
      points.push_back({u(rng) * 100, u(rng) * 100, u(rng) * 1});
    clouds["sparse"] = cloudFromPoints(points, std::vector<uint32_t>(points.size(), 0xFFFFFFFFu));
  }
  for (auto& [cloudName, original] : clouds) {
    PointCloud cloud = original;
    reorder(cloud, Order::Morton, 1);
    colorsAreIndices(cloud);
    GpuScene scene(*context, cloud, batched());
    // 800 x 500 and a larger one: the bigger the image, the more batches need more words.
    for (auto [w, h] : {std::pair<uint32_t, uint32_t>{800, 500}, {2400, 1500}}) {
      // And the overview from four times as far: small on screen, where one word holds whole batches.
      std::vector<std::pair<std::string, Camera>> cameras = views(cloud.bounds, double(w) / h);
      Camera distant = cameras.front().second;
      distant.eye = distant.target + 4.0 * (distant.eye - distant.target);
      cameras.push_back({"distant", distant});
      for (auto& [viewName, camera] : cameras) {
        std::string where =
            cloudName + " / " + viewName + " / " + std::to_string(w) + "x" + std::to_string(h);
        for (Method method : {pointMethod("batch"), pointMethod("batch-prefetch")}) {
          Drawn full = draw(*context, scene, camera, w, h, {method, 3});
          Drawn adaptive = draw(*context, scene, camera, w, h, {method, 0});
          size_t litFull = litCount(full.image), litAdaptive = litCount(adaptive.image);
          EXPECT_GE(double(litAdaptive), 0.995 * double(litFull)) << where;
          // Pixel of each visible point in the full-precision image.
          std::vector<int64_t> fullPixel(cloud.size() + 1, -1);
          for (size_t p = 0; p < full.image.size(); ++p)
            if (full.image[p]) fullPixel[full.image[p] & 0xFFFFFF] = int64_t(p);
          size_t compared = 0, moved = 0, tooFar = 0;
          for (size_t p = 0; p < adaptive.image.size(); ++p) {
            if (!adaptive.image[p]) continue;
            int64_t q = fullPixel[adaptive.image[p] & 0xFFFFFF];
            if (q < 0) continue;
            ++compared;
            int64_t dx = std::abs(int64_t(p % w) - q % w), dy = std::abs(int64_t(p / w) - q / w);
            moved += dx + dy > 0;
            tooFar += dx > 1 || dy > 1;
          }
          EXPECT_EQ(tooFar, 0u) << where << ": points moved by more than one pixel";
          EXPECT_GE(compared, litAdaptive / 2) << where << ": too few points to compare";
          if (cloudName == "sparse" && viewName == "overview" && w == 2400) {
            EXPECT_GE(compared, cloud.size() * 6 / 10) << where << ": most points should be visible";
            EXPECT_GE(compared, litAdaptive * 9 / 10) << where;
          }
          const BatchStats& s = *adaptive.stats.batch;
          if (viewName == "distant") {
            EXPECT_GT(s.pointsByWords[0], 0u) << where << ": adaptive precision never used one word";
          }
          if (method == pointMethod("batch") && w == 2400)
            std::printf("%-28s words 1/2/3: %8llu %8llu %8llu  compared %6zu, moved %5zu, lit %zu / %zu\n",
                        where.c_str(), (unsigned long long)s.pointsByWords[0],
                        (unsigned long long)s.pointsByWords[1], (unsigned long long)s.pointsByWords[2],
                        compared, moved, litAdaptive, litFull);
        }
      }
    }
  }
}

TEST_F(GpuTest, BatchCullingNeverDropsAVisiblePoint) {
  POINTRAST_REQUIRE_DATA();
  uint32_t w = 240, h = 160;
  for (auto& [cloudName, original] : testClouds()) {
    for (Order order : {Order::Original, Order::Morton}) {
      PointCloud cloud = original;
      reorder(cloud, order, 2);
      GpuScene scene(*context, cloud, batched());
      std::vector<std::pair<std::string, Camera>> cameras = views(cloud.bounds, double(w) / h);
      // And looking straight down from just above the middle with a narrow lens: most batches beside the
      // frustum, some across its sides.
      Camera down;
      down.eye = cloud.bounds.center() + glm::dvec3(0, 0, cloud.bounds.size().z);
      down.target = cloud.bounds.center();
      down.up = {0, 1, 0};
      down.fovY = 20;
      cameras.push_back({"down", down});
      size_t culledSomewhere = 0;
      for (auto& [viewName, camera] : cameras) {
        std::string where = cloudName + " / " + orderName(order) + " / " + viewName;
        for (uint32_t precision : {0u, 3u}) {
          Drawn culled =
              draw(*context, scene, camera, w, h, {pointMethod("batch-prefetch"), precision, true});
          Drawn all = draw(*context, scene, camera, w, h, {pointMethod("batch-prefetch"), precision, false});
          EXPECT_EQ(culled.words, all.words) << where << ", precision " << precision;
          EXPECT_EQ(all.stats.batch->batchesRendered, all.stats.batch->batchesProcessed) << where;
          culledSomewhere += culled.stats.batch->batchesRendered < culled.stats.batch->batchesProcessed;
          EXPECT_EQ(culled.stats.batch->pointsRendered > 0, all.stats.batch->pointsRendered > 0) << where;
        }
      }
      if (order == Order::Morton) { // (a random cloud in its own order has no batch smaller than the cloud)
        EXPECT_GT(culledSomewhere, 0u) << cloudName << ": no view culled anything";
      }
    }
  }
}

namespace {

// Five batches with known fates, seen by axisCamera() in a 32 x 48 image:
//   0: 10240 points on the 512 pixels of rows 0..15, 20 per pixel, point i on pixel i % 512 at step
//      s = i / 512. Both batch (thread t draws points t + 128 j) and batch-prefetch (points 4 (t + 128 j)
//      + k) give all points of a pixel to one thread in the order of s, so early-z is deterministic:
//      pixels 0..255 get their points front to back (1 atomic each), pixels 256..511 back to front (20).
//   1: 10240 points behind the eye: culled.
//   2: 10240 points left of the frustum: culled.
//   3: 10240 points at x = -50 and x = +50: the box crosses the frustum, no point is in the image.
//   4: 1000 points, one on each of 1000 pixels of rows 16..47.
constexpr uint32_t kHandW = 32, kHandH = 48;

PointCloud handBuiltBatches() {
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  auto atPixel = [&](uint32_t px, uint32_t py, double depth, uint32_t color) {
    // Normalized device coordinates of the pixel center; x / w = ndc x needs x = ndc x * depth * aspect.
    double sx = (px + 0.5) / (kHandW / 2.0) - 1.0, sy = 1.0 - (py + 0.5) / (kHandH / 2.0);
    points.push_back({sx * depth * kHandW / kHandH, sy * depth, -depth});
    colors.push_back(color);
  };
  for (uint32_t i = 0; i < 10240; ++i) {
    uint32_t r = i % 512, s = i / 512;
    double depth = r < 256 ? 2.0 + 0.05 * s : 3.0 - 0.05 * s;
    atPixel(r % 32, r / 32, depth, 0xFF000000u | (r * 97 + s * 13));
  }
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0, 1);
  for (uint32_t i = 0; i < 10240; ++i)
    points.push_back({u(rng) * 4 - 2, u(rng) * 4 - 2, 1 + u(rng)}), colors.push_back(0xFF0000FFu);
  for (uint32_t i = 0; i < 10240; ++i)
    points.push_back({-10 + 4 * u(rng), u(rng) - 0.5, -2 - u(rng)}), colors.push_back(0xFF00FF00u);
  for (uint32_t i = 0; i < 10240; ++i)
    points.push_back({i % 2 ? 50.0 : -50.0, 0.0, -2.0}), colors.push_back(0xFFFF0000u);
  for (uint32_t i = 0; i < 1000; ++i)
    atPixel(i % 32, 16 + i / 32, 2.5, 0xFF000000u | (i * 7919));
  return cloudFromPoints(points, colors);
}

} // namespace

TEST_F(GpuTest, BatchStatisticsAreExactOnAHandBuiltScene) {
  PointCloud cloud = handBuiltBatches();
  ASSERT_EQ(cloud.size(), 4 * 10240u + 1000);
  Camera camera = axisCamera();
  for (uint64_t partPoints : {uint64_t(0), uint64_t(10240), uint64_t(20480)}) {
    GpuScene scene(*context, cloud, batched(partPoints));
    for (Method method : {pointMethod("batch"), pointMethod("batch-prefetch"), pointMethod("batch-hqs")}) {
      for (uint32_t precision : {0u, 1u, 2u, 3u}) {
        std::string where = std::string(methodName(method)) + ", parts of " + std::to_string(partPoints) +
                            ", precision " + std::to_string(precision);
        Drawn d = draw(*context, scene, camera, kHandW, kHandH, {method, precision});
        ASSERT_TRUE(d.stats.batch) << where;
        const BatchStats& s = *d.stats.batch;
        EXPECT_EQ(s.batchesProcessed, 5u) << where;
        EXPECT_EQ(s.batchesRendered, 3u) << where;
        EXPECT_EQ(s.pointsProcessed, 10240u + 10240u + 1000u) << where;
        EXPECT_EQ(s.pointsRendered, 256u * 1 + 256u * 20 + 1000u) << where;
        EXPECT_EQ(s.pointsBlended, method == pointMethod("batch-hqs") ? 512u + 1000u : 0u) << where;
        if (precision != 0) {
          EXPECT_EQ(s.pointsByWords[precision - 1], s.pointsProcessed) << where;
        } else {
          EXPECT_EQ(s.pointsByWords[0], 11240u) << where << ": batches 0 and 4 span few pixels";
        }
        uint64_t words = s.pointsByWords[0] + 2 * s.pointsByWords[1] + 3 * s.pointsByWords[2];
        uint64_t once = 5 * 32 + 4 * words;
        EXPECT_EQ(s.bytesRead, method == pointMethod("batch-hqs") ? 2 * once + 4 * s.pointsBlended : once)
            << where;
        EXPECT_EQ(litCount(d.image), 1512u) << where;
      }
    }
  }
}

TEST_F(GpuTest, BatchPartsAndScenesGiveTheFramebufferOfOnePart) {
  std::mt19937_64 rng(13);
  PointCloud cloud = randomBoxCloud(rng, 100'000, {5, 5, 5});
  Camera camera = overviewCamera(cloud.bounds, 2.0);
  GpuScene whole(*context, cloud, batched());
  ASSERT_EQ(whole.parts().size(), 1u);
  GpuScene small(*context, cloud, batched(10240)); // 10 parts, the last one short
  ASSERT_EQ(small.parts().size(), 10u);
  // Three scenes cut at batch boundaries (so their batches are those of the whole upload), in parts of
  // two, three and one batch: 2 + 2 + 6 parts.
  std::vector<std::unique_ptr<GpuScene>> scenes;
  uint64_t cuts[] = {0, 40'960, 81'920, cloud.size()};
  uint64_t partSizes[] = {20'480, 30'720, 10'240};
  for (int s = 0; s < 3; ++s) {
    UploadOptions o = batched(partSizes[s]);
    o.first = cuts[s];
    o.count = cuts[s + 1] - cuts[s];
    scenes.push_back(std::make_unique<GpuScene>(*context, cloud, o));
  }
  const GpuScene* three[] = {scenes[0].get(), scenes[1].get(), scenes[2].get()};
  for (Method method : {pointMethod("batch"), pointMethod("batch-prefetch")}) {
    for (uint32_t precision : {0u, 3u}) {
      Drawn reference = draw(*context, whole, camera, 256, 128, {method, precision});
      EXPECT_GT(litCount(reference.image), 1000u);
      EXPECT_EQ(draw(*context, small, camera, 256, 128, {method, precision}).words, reference.words)
          << methodName(method) << ": ten parts";
      Drawn split = draw(*context, three, camera, 256, 128, {method, precision});
      EXPECT_EQ(split.words, reference.words) << methodName(method) << ": three scenes, ten parts";
      EXPECT_EQ(split.stats.batch->pointsProcessed, reference.stats.batch->pointsProcessed);
      EXPECT_EQ(split.stats.points, cloud.size());
    }
  }
}

// Only the last timed frame counts (the others draw with pipelines that count nothing): a render of several
// frames after warm-ups reports the counts of one frame and draws what a single frame draws.
TEST_F(GpuTest, BatchCountsAreThoseOfOneFrameWhateverTheFrames) {
  uint32_t w = 240, h = 160;
  std::mt19937_64 rng(5);
  PointCloud cloud = randomBoxCloud(rng, 60'000, {5, 5, 5});
  reorder(cloud, Order::Morton, 2);
  GpuScene scene(*context, cloud, batched());
  Camera camera = overviewCamera(cloud.bounds, double(w) / h);
  for (Method method : {pointMethod("batch"), pointMethod("batch-prefetch"), pointMethod("batch-hqs")}) {
    Drawn one = draw(*context, scene, camera, w, h, {method});
    Renderer renderer(*context, w, h);
    RenderSettings settings;
    settings.method = method;
    settings.captureWords = true;
    settings.background = 0;
    settings.warmup = 2;
    settings.frames = 3;
    FrameStats many = renderer.render(scene, camera, settings);
    ASSERT_TRUE(one.stats.batch && many.batch) << methodName(method);
    EXPECT_EQ(many.frames, 3u);
    EXPECT_EQ(many.batch->batchesProcessed, one.stats.batch->batchesProcessed) << methodName(method);
    EXPECT_EQ(many.batch->batchesRendered, one.stats.batch->batchesRendered) << methodName(method);
    EXPECT_EQ(many.batch->pointsProcessed, cloud.size()) << methodName(method);
    EXPECT_EQ(many.batch->pointsBlended, one.stats.batch->pointsBlended) << methodName(method);
    EXPECT_EQ(many.batch->bytesRead, one.stats.batch->bytesRead) << methodName(method);
    EXPECT_GT(many.batch->pointsRendered, 0u) << methodName(method);
    EXPECT_EQ(renderer.image(), one.image) << methodName(method);
  }
}

// The batches' decisions live in a buffer of the renderer, computed by a pass before the drawing: one
// renderer drawing a scene of more batches after one of fewer must grow it and draw what a fresh one draws.
TEST_F(GpuTest, TheBatchDecisionBufferGrowsWithTheScene) {
  uint32_t w = 240, h = 160;
  std::mt19937_64 rng(17);
  PointCloud small = randomBoxCloud(rng, 20'000, {5, 5, 5}), large = randomBoxCloud(rng, 90'000, {5, 5, 5});
  GpuScene smallScene(*context, small, batched()), largeScene(*context, large, batched());
  Camera camera = overviewCamera(large.bounds, double(w) / h);
  for (Method method : {pointMethod("batch-prefetch"), pointMethod("batch-hqs")}) {
    Renderer renderer(*context, w, h);
    RenderSettings settings;
    settings.method = method;
    settings.captureWords = true;
    settings.background = 0;
    renderer.render(smallScene, camera, settings);
    renderer.render(largeScene, camera, settings);
    Drawn fresh = draw(*context, largeScene, camera, w, h, {method});
    EXPECT_GT(litCount(fresh.image), 1000u) << methodName(method);
    if (method == pointMethod("batch-prefetch"))
      EXPECT_EQ(renderer.framebufferWords(), fresh.words);
    else
      EXPECT_EQ(renderer.image(), fresh.image) << methodName(method);
  }
}

TEST_F(GpuTest, BatchLayoutAndPartLimitsAreClearErrors) {
  PointCloud cloud = cloudFromPoints({{0, 0, -1}, {0.1, 0, -1}}, {0xFFFFFFFFu, 0xFF0000FFu});
  GpuScene floatScene(*context, cloud, floats());
  GpuScene batchScene(*context, cloud, batched());
  Renderer renderer(*context, 8, 8);
  RenderSettings settings;
  settings.method = pointMethod("batch");
  EXPECT_THROW(renderer.render(floatScene, axisCamera(), settings), InputError);
  settings.method = pointMethod("atomicmin");
  EXPECT_THROW(renderer.render(batchScene, axisCamera(), settings), InputError);
  settings.method = pointMethod("hw-points");
  EXPECT_THROW(renderer.render(batchScene, axisCamera(), settings), InputError);
  settings.method = pointMethod("batch-prefetch");
  settings.precision = 4;
  EXPECT_THROW(renderer.render(batchScene, axisCamera(), settings), InputError);
  settings.precision = 0;
  // 65 parts (of one batch each, over 5 scenes) is one more than visibility indices address.
  std::vector<glm::dvec3> many(13 * 10240, glm::dvec3(0, 0, -1));
  PointCloud big = cloudFromPoints(many, std::vector<uint32_t>(many.size(), 0xFFFFFFFFu));
  std::vector<std::unique_ptr<GpuScene>> scenes;
  std::vector<const GpuScene*> drawn;
  for (int s = 0; s < 5; ++s) {
    scenes.push_back(std::make_unique<GpuScene>(*context, big, batched(10240)));
    drawn.push_back(scenes.back().get());
  }
  try {
    renderer.render(drawn, axisCamera(), settings);
    ADD_FAILURE() << "65 parts were drawn";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("65 parts"), std::string::npos) << e.what();
  }
  drawn.pop_back();
  drawn.push_back(&batchScene); // 53 parts: fine
  FrameStats stats = renderer.render(drawn, axisCamera(), settings);
  EXPECT_EQ(stats.batch->batchesProcessed, 53u);
}

namespace {

int maxChannelDiff(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b,
                   double* withinOne = nullptr) {
  int worst = 0;
  size_t ok = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    int d = 0;
    for (int c = 0; c < 4; ++c)
      d = std::max(d, std::abs(int((a[i] >> (8 * c)) & 0xFF) - int((b[i] >> (8 * c)) & 0xFF)));
    worst = std::max(worst, d);
    ok += d <= 1;
  }
  if (withinOne) *withinOne = double(ok) / double(a.size());
  return worst;
}

} // namespace

TEST_F(GpuTest, BatchHqsMatchesHqs) {
  // As methods_test's HQS case: points near pixel centers at depths well within 1 % of the pixel's front
  // surface or 3 % behind it, one pixel with 1,500 blended points (past the packed word's 255).
  constexpr uint32_t W = 64, H = 64;
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3), layer(0.0, 0.004);
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  auto add = [&](uint32_t px, uint32_t py, double depth, uint32_t color) {
    double sx = (px + 0.5 + jitter(rng)) / (W / 2.0) - 1.0, sy = 1.0 - (py + 0.5 + jitter(rng)) / (H / 2.0);
    points.push_back({sx * depth, sy * depth, -depth});
    colors.push_back(color);
  };
  for (uint32_t py = 0; py < H; ++py)
    for (uint32_t px = 0; px < W; ++px) {
      if ((px * 7 + py * 3) % 11 == 0) continue;
      double front = 2.0 + 0.5 * std::sin(px * 0.2) + 0.3 * std::cos(py * 0.3);
      int count = 1 + int(rng() % 6);
      for (int k = 0; k < count; ++k)
        add(px, py, front * (1.0 + layer(rng)), 0xFF000000u | uint32_t(rng() & 0xFFFFFF));
      add(px, py, front * 1.03, 0xFF0000FFu);
    }
  for (int k = 0; k < 1500; ++k)
    add(10, 20, 1.5 * (1.0 + layer(rng)), 0xFF000000u | uint32_t(rng() & 0xFFFFFF));
  PointCloud cloud = cloudFromPoints(points, colors, 1e-7);
  for (Order order : {Order::Original, Order::Shuffled}) {
    PointCloud ordered = cloud;
    reorder(ordered, order, 1);
    GpuScene floatScene(*context, ordered, floats());
    GpuScene batchScene(*context, ordered, batched(10240));
    std::vector<uint32_t> hqs = draw(*context, floatScene, axisCamera(), W, H, {pointMethod("hqs")}).image;
    for (uint32_t precision : {3u, 0u}) {
      Drawn b = draw(*context, batchScene, axisCamera(), W, H, {pointMethod("batch-hqs"), precision});
      EXPECT_TRUE(b.words.empty());
      EXPECT_LE(maxChannelDiff(b.image, hqs), 1) << orderName(order) << ", precision " << precision;
      EXPECT_NE(b.image[20 * W + 10], 0u);
    }
  }
  // Generated terrain: almost every pixel within 1 (points on pixel borders may switch pixels).
  GenerateOptions options;
  options.points = 80'000;
  options.progress = false;
  PointCloud terrain = generateScene(Scene::Terrain, options);
  reorder(terrain, Order::Morton, 1);
  Camera camera = overviewCamera(terrain.bounds, 1.6);
  GpuScene floatScene(*context, terrain, floats());
  GpuScene batchScene(*context, terrain, batched());
  std::vector<uint32_t> hqs = draw(*context, floatScene, camera, 320, 200, {pointMethod("hqs")}).image;
  Drawn b = draw(*context, batchScene, camera, 320, 200, {pointMethod("batch-hqs"), 3});
  double withinOne = 0;
  maxChannelDiff(b.image, hqs, &withinOne);
  EXPECT_GE(withinOne, 0.998);
  EXPECT_GT(b.stats.batch->pointsBlended, litCount(b.image));
}

} // namespace pointrast::test

namespace pointrast::test {

// batch-hqs draws dense batches (many points a pixel) in one pass, and takes back the pixels where a dense
// batch blended a point beyond 1 % of the closest depth. The image and the points blended are exactly those
// of two passes over every batch: at overview densities in Morton and original order, with a second layer
// behind the terrain mixed into the same batches (pixels taken back), and where few batches are dense.
TEST_F(GpuTest, BatchHqsDenseBatchesGiveTheTwoPassImage) {
  GenerateOptions options;
  options.points = 1'000'000;
  options.progress = false;
  PointCloud terrain = generateScene(Scene::Terrain, options);
  // Seen from 20 times the overview's distance (with a 20 times narrower field of view), a batch of a million
  // points spans as little depth as one of a billion does from the overview.
  auto farther = [](Camera c) {
    c.eye = c.target + 20.0 * (c.eye - c.target);
    c.fovY /= 20.0;
    return c;
  };
  const Camera camera = farther(overviewCamera(terrain.bounds, 160.0 / 72.0));
  // The second layer: every point again, lower by 3 % of the camera's distance, so that where both project
  // the lower one lies beyond 1 % of the closest depth: its dense batches blend points that are taken back.
  ASSERT_TRUE(terrain.hasColor());
  PointCloud layers = terrain;
  const double drop = 0.03 * glm::length(camera.eye - terrain.bounds.center());
  const int32_t steps = int32_t(std::lround(drop / terrain.scale.z));
  for (uint64_t i = 0; i < terrain.size(); ++i) {
    layers.positions.insert(layers.positions.end(), {terrain.positions[3 * i], terrain.positions[3 * i + 1],
                                                     terrain.positions[3 * i + 2] - steps});
    layers.colors.push_back(~terrain.colors[i] | 0xFF000000u);
  }
  computeBounds(layers);
  // From straight above.
  Camera above;
  const glm::dvec3 size = terrain.bounds.max - terrain.bounds.min;
  above.eye = terrain.bounds.center() + glm::dvec3(0, 0, 1.2 * std::max(size.x, size.y));
  above.target = terrain.bounds.center();
  above.up = {0, 1, 0};
  above = farther(above);
  struct Case {
    const char* name;
    const PointCloud* cloud;
    Camera camera;
    Order order;
    uint32_t w, h;
  };
  for (const Case& c : {Case{"terrain, Morton, 160x72", &terrain, camera, Order::Morton, 160, 72},
                        Case{"terrain, original order, 160x72", &terrain, camera, Order::Original, 160, 72},
                        Case{"two layers, Morton, 160x72", &layers, camera, Order::Morton, 160, 72},
                        Case{"terrain from above, Morton, 160x72", &terrain, above, Order::Morton, 160, 72},
                        Case{"two layers from above, Morton, 160x72", &layers, above, Order::Morton, 160, 72},
                        Case{"terrain, Morton, 960x432", &terrain, camera, Order::Morton, 960, 432}}) {
    PointCloud ordered = *c.cloud;
    reorder(ordered, c.order, 1);
    GpuScene scene(*context, ordered, batched());
    forgetRenderers(); // the first frame of this scene decides from nothing drawn before
    // The first frame, and the next: batches drawn again in the first are not dense in the second.
    Drawn one = draw(*context, scene, c.camera, c.w, c.h, {pointMethod("batch-hqs"), 0, true, true, 0});
    Drawn next = draw(*context, scene, c.camera, c.w, c.h, {pointMethod("batch-hqs"), 0, true, true, 1});
    Drawn two = draw(*context, scene, c.camera, c.w, c.h, {pointMethod("batch-hqs"), 0, true, false});
    const BatchStats& s1 = *one.stats.batch;
    const BatchStats& s2 = *two.stats.batch;
    EXPECT_TRUE(one.image == two.image) << c.name;
    EXPECT_TRUE(next.image == two.image) << c.name;
    EXPECT_EQ(next.stats.batch->pointsBlended, s2.pointsBlended) << c.name;
    EXPECT_EQ(next.stats.batch->batchesRedrawn, 0u) << c.name;
    EXPECT_EQ(next.stats.batch->batchesDense, s1.batchesDense - s1.batchesRedrawn) << c.name;
    EXPECT_EQ(s1.pointsBlended, s2.pointsBlended) << c.name;
    EXPECT_EQ(s1.pointsProcessed, s2.pointsProcessed) << c.name;
    EXPECT_EQ(s2.batchesDense, 0u) << c.name;
    // Morton order at overview density: most batches dense (in scan order and at 960x432 few or none are).
    if (c.order == Order::Morton && c.w == 160) {
      EXPECT_GT(s1.batchesDense, s1.batchesRendered / 2) << c.name;
    }
    if (c.cloud == &layers) {
      EXPECT_GT(s1.pointsTakenBack, 0u) << c.name;
    }
    EXPECT_GT(litCount(one.image), 1000u) << c.name;
    std::printf("%s: %zu pixels lit, %llu of %llu batches dense, %llu redrawn, %llu points taken back, %llu "
                "blended\n",
                c.name, litCount(one.image), (unsigned long long)s1.batchesDense,
                (unsigned long long)s1.batchesRendered, (unsigned long long)s1.batchesRedrawn,
                (unsigned long long)s1.pointsTakenBack, (unsigned long long)s1.pointsBlended);
  }
}

} // namespace pointrast::test

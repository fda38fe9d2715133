// hw-points, the hardware point-list baseline, against the image contract and against atomicmin:
// - hand-built points land on their pixels, the nearer of two points wins whatever the draw order (also
//   0.1 % apart at 1e5 near-plane distances, where a standard 1 - near/w depth would tie), points behind
//   the eye, before the near plane or outside the image are dropped, the background is exact;
// - on a random cloud, generated terrain and autzen_trim.las, in four orders and two views, hw-points and
//   atomicmin agree on >= 99 % of pixels (docs/design.md, "Equivalence": they differ only by rounding at pixel
//   borders, where the hardware snaps to subpixels, and by which of two equally deep points wins).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>

#include "base/error.h"
#include "cloud/generate.h"
#include "cloud/order.h"
#include "gpu_fixture.h"
#include "io/reader.h"
#include "render/renderer.h"
#include "test_data.h"

namespace pointrast::test {

namespace {

std::vector<uint32_t> renderImage(gpu::Context& context, const GpuScene& scene, const Camera& camera,
                                  uint32_t w, uint32_t h, Method method, uint32_t background = 0) {
  Renderer renderer(context, w, h);
  RenderSettings settings;
  settings.method = method;
  settings.background = background;
  renderer.render(scene, camera, settings);
  return renderer.image();
}

struct Agreement {
  double all = 0; // equal pixels / all pixels
  double lit = 0; // equal pixels / pixels lit in either image
};

Agreement agreement(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
  size_t same = 0, lit = 0, litSame = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    same += a[i] == b[i];
    if (a[i] == 0 && b[i] == 0) continue;
    ++lit;
    litSame += a[i] == b[i];
  }
  return {double(same) / double(a.size()), lit ? double(litSame) / double(lit) : 1.0};
}

std::vector<std::pair<std::string, Camera>> views(const Bounds& bounds, double aspect) {
  Camera inside;
  inside.eye = bounds.center() + 0.1 * (bounds.max - bounds.center());
  inside.target = bounds.max;
  return {{"overview", overviewCamera(bounds, aspect)}, {"inside", inside}};
}

// hw-points against atomicmin for every order and view of a cloud; returns the worst agreement over all
// pixels.
double compareWithAtomicMin(gpu::Context& context, const std::string& name, const PointCloud& original,
                            uint32_t w, uint32_t h) {
  double worst = 1.0;
  for (Order order : {Order::Original, Order::Morton, Order::Shuffled, Order::ShuffledMorton}) {
    PointCloud cloud = original;
    reorder(cloud, order, 5);
    UploadOptions upload;
    upload.progress = false;
    GpuScene scene(context, cloud, upload);
    for (auto& [viewName, camera] : views(cloud.bounds, double(w) / h)) {
      std::vector<uint32_t> reference = renderImage(context, scene, camera, w, h, pointMethod("atomicmin"));
      std::vector<uint32_t> hw = renderImage(context, scene, camera, w, h, pointMethod("hw-points"));
      Agreement a = agreement(hw, reference);
      std::printf("hw-points vs atomicmin, %-8s %-16s %-8s: %.3f %% of pixels equal, %.3f %% of lit pixels\n",
                  name.c_str(), orderName(order), viewName.c_str(), 100 * a.all, 100 * a.lit);
      EXPECT_GE(a.all, 0.99) << name << " / " << orderName(order) << " / " << viewName;
      worst = std::min(worst, a.all);
    }
  }
  return worst;
}

constexpr uint32_t kRed = 0xFF0000FFu, kGreen = 0xFF00FF00u, kBlue = 0xFFFF0000u;
constexpr uint32_t kYellow = 0xFF00FFFFu, kMagenta = 0xFFFF00FFu;

} // namespace

TEST_F(GpuTest, HwPointsHandBuiltContract) {
  // 4x4 image, aspect 1, points at pixel centers (no border rounding):
  //   red (2,1) at depth 1, with green at depth 2 on the same pixel drawn before or after it;
  //   blue (0,3);
  //   on (1,2) magenta at depth 1000, drawn first, and yellow 0.1 % nearer: 1e5 near planes away
  //   (near = 0.01) a standard 1 - near/w depth would round both to one D32 value and keep magenta;
  //   dropped: behind the eye (would land on (0,1)), between eye and near plane (would land on (3,1)),
  //   outside the image.
  constexpr uint32_t kBackground = 0x80402010u;
  for (bool greenFirst : {false, true}) {
    std::vector<glm::dvec3> points = {{0.25, 0.25, -1}, {0.5, 0.5, -2}};
    std::vector<uint32_t> colors = {kRed, kGreen};
    if (greenFirst) {
      std::swap(points[0], points[1]);
      std::swap(colors[0], colors[1]);
    }
    double nearer = 1000 * (1 - 0.001);
    points.insert(points.end(), {{-0.75, -0.75, -1},
                                 {-250, -250, -1000},
                                 {-0.25 * nearer, -0.25 * nearer, -nearer},
                                 {0.75, -0.25, 1},
                                 {0.00375, 0.00125, -0.005},
                                 {3, 0, -1}});
    colors.insert(colors.end(), {kBlue, kMagenta, kYellow, kGreen, kGreen, kGreen});
    PointCloud cloud = cloudFromPoints(points, colors);
    UploadOptions upload;
    upload.progress = false;
    GpuScene scene(*context, cloud, upload);
    std::vector<uint32_t> image =
        renderImage(*context, scene, axisCamera(), 4, 4, pointMethod("hw-points"), kBackground);
    for (uint32_t i = 0; i < 16; ++i) {
      uint32_t x = i % 4, y = i / 4;
      uint32_t expected = x == 2 && y == 1   ? kRed
                          : x == 0 && y == 3 ? kBlue
                          : x == 1 && y == 2 ? kYellow
                                             : kBackground;
      EXPECT_EQ(image[i], expected) << "pixel " << x << "," << y
                                    << (greenFirst ? " (green drawn first)" : "");
    }
    EXPECT_EQ(renderImage(*context, scene, axisCamera(), 4, 4, pointMethod("atomicmin"), kBackground), image);
  }
}

TEST_F(GpuTest, HwPointsAgreesWithAtomicMinOnRandomCloud) {
  std::mt19937_64 rng(23);
  compareWithAtomicMin(*context, "random", randomBoxCloud(rng, 100'000, {20, 10, 5}), 160, 100);
}

TEST_F(GpuTest, HwPointsAgreesWithAtomicMinOnTerrain) {
  GenerateOptions options;
  options.points = 200'000;
  options.progress = false;
  compareWithAtomicMin(*context, "terrain", generateScene(Scene::Terrain, options), 320, 180);
}

TEST_F(GpuTest, HwPointsAgreesWithAtomicMinOnAutzen) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  std::filesystem::path file = dataDir() / "las/autzen_trim.las";
  ASSERT_TRUE(std::filesystem::exists(file)) << file << " is missing (../shared/data)";
  io::ReadOptions read;
  read.progress = false;
  compareWithAtomicMin(*context, "autzen", io::readCloud(file, read), 400, 225);
}

TEST_F(GpuTest, HwPointsDrawsPartsAndScenesInOrder) {
  // Parts are drawn one after another in point order, so splitting a cloud into parts or scenes changes
  // nothing, not even which of two equally deep points wins.
  GenerateOptions options;
  options.points = 50'000;
  options.progress = false;
  PointCloud cloud = generateScene(Scene::Terrain, options);
  Camera camera = overviewCamera(cloud.bounds, 2.0);
  UploadOptions whole;
  whole.progress = false;
  std::vector<uint32_t> reference =
      renderImage(*context, GpuScene(*context, cloud, whole), camera, 256, 128, pointMethod("hw-points"));
  UploadOptions small = whole;
  small.maxPartPoints = 10240; // 5 parts, the last one short
  EXPECT_EQ(
      renderImage(*context, GpuScene(*context, cloud, small), camera, 256, 128, pointMethod("hw-points")),
      reference);

  std::vector<std::unique_ptr<GpuScene>> scenes;
  uint64_t cuts[] = {0, 20'001, cloud.size()};
  for (int s = 0; s < 2; ++s) {
    UploadOptions o = whole;
    o.first = cuts[s];
    o.count = cuts[s + 1] - cuts[s];
    scenes.push_back(std::make_unique<GpuScene>(*context, cloud, o));
  }
  const GpuScene* drawn[] = {scenes[0].get(), scenes[1].get()};
  Renderer renderer(*context, 256, 128);
  RenderSettings settings;
  settings.method = pointMethod("hw-points");
  settings.background = 0;
  settings.frames = 3; // several frames in one command buffer: the barriers between them must hold
  FrameStats stats = renderer.render(drawn, camera, settings);
  EXPECT_EQ(renderer.image(), reference);
  EXPECT_GT(stats.medianMs, 0.0);
  EXPECT_EQ(stats.points, cloud.size());
}

TEST_F(GpuTest, HwPointsHasNoInt40Depth) {
  PointCloud cloud = cloudFromPoints({{0, 0, -1}}, {kRed});
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(*context, cloud, upload);
  Renderer renderer(*context, 8, 8);
  RenderSettings settings;
  settings.method = pointMethod("hw-points");
  settings.depth = DepthMode::Int40;
  EXPECT_THROW(renderer.render(scene, axisCamera(), settings), InputError);
  EXPECT_EQ(parseMethod("hw-points"), pointMethod("hw-points"));
}

} // namespace pointrast::test

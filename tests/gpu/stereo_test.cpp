// Stereo rendering (render/stereo.h): both eyes in one pass with the batch and LOD methods.
// - eye cameras: the eyes sit the separation apart, look in parallel, and a point on the convergence plane
//   straight ahead lands on the same pixel in both; an infinite convergence distance gives no shift;
// - each half of a stereo frame is bit-identical (image and words) to a mono frame from that eye, for
//   batch, batch-prefetch, batch-hqs, lod and lod-hqs, with scenes in several parts, with LOD frames drawn in
//   passes, with the resolve stage, and with the cross-eyed layout;
// - a stereo frame selects the union of both eyes' nodes (never fewer than either eye alone);
// - methods that cannot draw stereo frames say so.
#include <algorithm>
#include <random>

#include "base/error.h"
#include "cloud/generate.h"
#include "gpu_fixture.h"
#include "lod_octree.h"
#include "render/lod/lod_scene.h"
#include "render/renderer.h"
#include "render/stereo.h"

namespace pointrast::test {

namespace {

constexpr uint32_t kWidth = 80, kHeight = 60;

struct Image {
  std::vector<uint32_t> pixels;
  std::vector<uint64_t> words; // empty for methods without canonical words (and no resolve stage)
};

// The half `half` of a side-by-side frame.
template <class T> std::vector<T> halfOf(const std::vector<T>& wide, uint32_t half) {
  std::vector<T> out;
  for (uint32_t y = 0; y < kHeight; ++y) {
    auto row = wide.begin() + std::ptrdiff_t(uint64_t(y) * 2 * kWidth + uint64_t(half) * kWidth);
    out.insert(out.end(), row, row + kWidth);
  }
  return out;
}

size_t lit(const std::vector<uint32_t>& image) {
  return size_t(std::count_if(image.begin(), image.end(), [](uint32_t c) { return c != 0xFF000000u; }));
}

RenderSettings settingsFor(const char* method, const StereoSettings& stereo) {
  RenderSettings s;
  s.method = parseMethod(method);
  s.stereo = stereo;
  s.captureWords = true;
  s.frames = 1;
  s.warmup = 0;
  s.minNodePx = 0;
  return s;
}

bool keepsWords(const RenderSettings& s) {
  return hasCanonicalWords(methodInfo(s.method)) || s.post.enabled();
}

// A stereo frame and the two mono frames of its eyes, drawn by `draw(renderer, camera, settings)`.
template <class Draw>
void expectHalvesEqualMonoEyes(gpu::Context& context, const Camera& camera, const RenderSettings& s,
                               const std::string& what, Draw&& draw) {
  Renderer stereo(context, kWidth, kHeight, 2);
  ASSERT_EQ(stereo.width(), 2 * kWidth);
  draw(stereo, camera, s);
  const std::vector<uint32_t> wide = stereo.image();
  const std::vector<uint64_t> wideWords = keepsWords(s) ? stereo.framebufferWords() : std::vector<uint64_t>{};
  std::vector<uint32_t> halves[2];
  for (uint32_t half = 0; half < 2; ++half) {
    const Eye eye = eyeOfHalf(s.stereo, half);
    Renderer mono(context, kWidth, kHeight);
    draw(mono, eyeCamera(camera, s.stereo, eye, double(kWidth) / kHeight), s);
    const std::vector<uint32_t> image = mono.image();
    halves[half] = halfOf(wide, half);
    EXPECT_GT(lit(image), 200u) << what;
    EXPECT_EQ(halves[half], image) << what << ", half " << half;
    if (keepsWords(s)) {
      EXPECT_EQ(halfOf(wideWords, half), mono.framebufferWords()) << what << ", half " << half;
    }
  }
  EXPECT_NE(halves[0], halves[1]) << what << ": the eyes see the scene from different places";
}

PointCloud terrain(uint64_t points) {
  GenerateOptions options;
  options.points = points;
  options.progress = false;
  return generateScene(Scene::Terrain, options);
}

} // namespace

TEST(StereoCameras, EyesAreApartParallelAndConverge) {
  Camera c;
  c.eye = {10, 0, 0};
  c.target = {10, 20, 0};
  c.up = {0, 0, 1};
  StereoSettings s;
  s.separation = 0.5;
  s.convergence = 8;
  const double aspect = 1.5;
  const Camera left = eyeCamera(c, s, Eye::Left, aspect), right = eyeCamera(c, s, Eye::Right, aspect);
  EXPECT_NEAR(glm::length(right.eye - left.eye), 0.5, 1e-12);
  EXPECT_NEAR(glm::length((left.target - left.eye) - (right.target - right.eye)), 0, 1e-12) << "parallel";
  EXPECT_GT(right.eye.x, left.eye.x) << "right is to the right (+x when looking along +y with z up)";
  // A point on the convergence plane straight ahead: the same normalized device coordinates in both eyes.
  const glm::dvec4 p{10, 8, 0, 1};
  const glm::dvec4 l = viewProjection(left, {}, aspect) * p, r = viewProjection(right, {}, aspect) * p;
  EXPECT_NEAR(l.x / l.w, 0, 1e-12);
  EXPECT_NEAR(r.x / r.w, 0, 1e-12);
  EXPECT_NEAR(l.y / l.w, r.y / r.w, 1e-12);
  // Nearer points lie more to the right in the left eye (crossed parallax: in front of the screen).
  const glm::dvec4 near{10, 4, 0, 1};
  const glm::dvec4 ln = viewProjection(left, {}, aspect) * near,
                   rn = viewProjection(right, {}, aspect) * near;
  EXPECT_GT(ln.x / ln.w, rn.x / rn.w);
  // Parallel frusta: no shift; the default separation is the 1/30 rule of the target's distance.
  s.convergence = std::numeric_limits<double>::infinity();
  s.separation = 0;
  EXPECT_EQ(eyeCamera(c, s, Eye::Left, aspect).shiftX, 0.0);
  EXPECT_NEAR(eyeSeparation(c, s), 20.0 / 30.0, 1e-12);
  s.convergence = 0;
  EXPECT_NEAR(convergenceDistance(c, s), 20.0, 1e-12);
  s.crossed = true;
  EXPECT_EQ(eyeOfHalf(s, 0), Eye::Right);
  EXPECT_THROW(parseConvergence("-1"), InputError);
  EXPECT_THROW(parseConvergence("x"), InputError);
  EXPECT_TRUE(std::isinf(parseConvergence("inf")));
}

TEST_F(GpuTest, StereoBatchHalvesEqualMonoEyes) {
  const PointCloud cloud = terrain(200'000);
  UploadOptions upload;
  upload.layout = SceneLayout::Batched;
  upload.progress = false;
  upload.maxPartPoints = 61'440; // four parts: the right eye's matrix is per part
  GpuScene scene(*context, cloud, upload);
  ASSERT_GT(scene.parts().size(), 1u);
  const Camera camera = overviewCamera(cloud.bounds, double(kWidth) / kHeight);
  StereoSettings stereo;
  stereo.separation = 0.05 * glm::length(camera.target - camera.eye);
  auto draw = [&](Renderer& r, const Camera& c, const RenderSettings& s) { r.render(scene, c, s); };
  for (const char* method : {"batch", "batch-prefetch", "batch-hqs"}) {
    for (uint32_t precision : {0u, 3u}) {
      RenderSettings s = settingsFor(method, stereo);
      s.precision = precision;
      expectHalvesEqualMonoEyes(*context, camera, s,
                                std::string(method) + " precision " + std::to_string(precision), draw);
    }
  }
  // The cross-eyed layout swaps the halves; the resolve stage runs on each eye's half alone.
  RenderSettings s = settingsFor("batch-prefetch", stereo);
  s.stereo.crossed = true;
  s.post.dilate = 2;
  s.post.pointSize = 2;
  s.post.edlStrength = 1;
  expectHalvesEqualMonoEyes(*context, camera, s, "crossed, resolve stage", draw);
  // A close view: batches straddle the image's borders and the near plane, and the eyes differ in culling.
  Camera close;
  close.eye = cloud.bounds.center() + glm::dvec3(0, 0, 0.02 * cloud.bounds.diagonal());
  close.target = close.eye + glm::dvec3(1, 1, -0.3);
  expectHalvesEqualMonoEyes(*context, close, settingsFor("batch", stereo), "close", draw);
}

TEST_F(GpuTest, StereoLodHalvesEqualMonoEyes) {
  MemoryOctree tree;
  std::mt19937_64 rng(17);
  buildOctree(tree, randomBoxCloud(rng, 60'000, {20, 10, 5}), 1500);
  tree.colorsAreIndices();
  const PointCloud all = tree.cloud();
  const Camera camera = overviewCamera(all.bounds, double(kWidth) / kHeight);
  StereoSettings stereo;
  stereo.separation = 2;
  for (uint64_t cache : {uint64_t(64) << 20, uint64_t(6) * shared::kLodPageBytes}) {
    auto draw = [&](Renderer& r, const Camera& c, const RenderSettings& s) {
      lod::LodOptions o;
      o.gpuBytes = cache;
      o.readers = 2;
      o.stagingBytes = 8ull << 20;
      lod::LodScene scene(*context, tree, o);
      const FrameStats stats = r.render(scene, c, s);
      if (cache < (1u << 20)) {
        EXPECT_GT(stats.lod->passes, 1u);
      }
    };
    for (const char* method : {"lod", "lod-hqs"})
      for (uint32_t precision : {0u, 3u}) {
        RenderSettings s = settingsFor(method, stereo);
        s.precision = precision;
        expectHalvesEqualMonoEyes(*context, camera, s,
                                  std::string(method) + " precision " + std::to_string(precision) +
                                      (cache < (1u << 20) ? " in passes" : ""),
                                  draw);
      }
  }
}

TEST_F(GpuTest, StereoLodSelectsTheUnionOfBothEyes) {
  MemoryOctree tree;
  std::mt19937_64 rng(18);
  buildOctree(tree, randomBoxCloud(rng, 60'000, {20, 10, 5}), 1000);
  const PointCloud all = tree.cloud();
  Camera camera;
  // Inside the box, looking along +x: each frustum's sides cut the cloud where the other's do not.
  camera.eye = all.bounds.center() + glm::dvec3(-12, 0, 0);
  camera.target = all.bounds.center() + glm::dvec3(10, 0, 0);
  StereoSettings stereo;
  stereo.separation = 6; // far apart: the eyes see different nodes at the frustum's sides
  RenderSettings s = settingsFor("lod", stereo);
  s.minNodePx = 3; // a few levels in an 80 x 60 image
  lod::LodOptions o;
  o.readers = 2;
  // Node names (ids depend on the order a scene learns of nodes).
  auto selected = [&](const std::vector<Camera>& views) {
    lod::LodScene scene(*context, tree, o);
    const lod::Selection sel = scene.selectAll(views, kWidth, kHeight, {s.minNodePx, 0, {}});
    std::vector<std::string> names;
    for (uint32_t id : sel.nodes)
      names.push_back(scene.hierarchy().node(id).info.key.potreeName());
    std::sort(names.begin(), names.end());
    return names;
  };
  const double aspect = double(kWidth) / kHeight;
  const Camera left = eyeCamera(camera, stereo, Eye::Left, aspect);
  const Camera right = eyeCamera(camera, stereo, Eye::Right, aspect);
  const std::vector<std::string> both = selected({left, right}), l = selected({left}), r = selected({right});
  std::vector<std::string> united;
  std::set_union(l.begin(), l.end(), r.begin(), r.end(), std::back_inserter(united));
  EXPECT_EQ(both, united);
  EXPECT_GT(both.size(), l.size());
  EXPECT_GT(both.size(), r.size());
}

TEST_F(GpuTest, StereoWithAMethodThatDrawsOneViewIsAClearError) {
  const PointCloud cloud = terrain(10'000);
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(*context, cloud, upload);
  Renderer stereo(*context, kWidth, kHeight, 2);
  RenderSettings s = settingsFor("atomicmin", {});
  try {
    stereo.render(scene, overviewCamera(cloud.bounds, 1.0), s);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("batch and LOD methods"), std::string::npos) << e.what();
  }
}

} // namespace pointrast::test

// The LOD methods (lod, lod-hqs) and their streaming node cache (render/lod/):
// - with no LOD culling and no budget, lod draws every point and matches atomicmin of the same points on
//   >= 99.9 % of lit pixels at full precision, and lod-hqs matches hqs within 1 per channel;
// - a node cache of a tenth of the octree (the selection drawn in passes) gives the bit-identical image;
// - nodes outside the view frustum are never drawn, and the statistics are exact on a hand-built octree;
// - the frame-by-frame loop draws resident ancestors first, converges to the offline image, and says when
//   nothing changed; eviction keeps the cache within its budget across camera jumps;
// - a node or a hierarchy part that fails to read while streaming ends with that one error, never a hang.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "base/error.h"
#include "cloud/generate.h"
#include "gpu/buffer.h"
#include "gpu/shader_registry.h"
#include "gpu/shared_types.h"
#include "gpu/spirv_reflect.h"
#include "gpu_fixture.h"
#include "io/writer.h"
#include "lod_octree.h"
#include "render/lod/lod_render.h"
#include "render/renderer.h"

namespace pointrast::test {

namespace {

struct LodDraw {
  bool hqs = false;
  uint32_t precision = 0;
  double minNodePx = 0;
  uint64_t pointBudget = 0;
  uint64_t gpuBytes = 64ull << 20;
};

struct LodDrawn {
  std::vector<uint64_t> words;
  std::vector<uint32_t> image;
  lod::LodRenderResult result;
};

Targets makeTargets(gpu::Context& context, uint32_t w, uint32_t h) {
  Targets t;
  t.width = w;
  t.height = h;
  t.framebuffer =
      gpu::Buffer(context, t.pixels() * 8, gpu::kBufferUsage, gpu::MemoryKind::Device, "framebuffer");
  t.image = gpu::Buffer(context, t.pixels() * 4, gpu::kBufferUsage, gpu::MemoryKind::Device, "image");
  t.words = gpu::Buffer(context, t.pixels() * 8, gpu::kBufferUsage, gpu::MemoryKind::Device, "words");
  return t;
}

lod::LodOptions smallOptions(uint64_t gpuBytes) {
  lod::LodOptions o;
  o.gpuBytes = gpuBytes;
  o.readers = 2;
  o.stagingBytes = 8ull << 20;
  return o;
}

RenderSettings lodSettings(uint32_t precision) {
  RenderSettings s;
  s.precision = precision;
  s.captureWords = true;
  s.background = 0;
  s.frames = 1;
  s.warmup = 0;
  return s;
}

LodDrawn drawOctree(gpu::Context& context, lod::NodeSource& source, const Camera& camera, uint32_t w,
                    uint32_t h, const LodDraw& d) {
  Targets targets = makeTargets(context, w, h);
  lod::LodScene scene(context, source, smallOptions(d.gpuBytes));
  lod::LodPasses passes(context, d.hqs, w, h);
  lod::LodView view{d.minNodePx, d.pointBudget};
  LodDrawn out;
  out.result = lod::renderOctree(context, scene, passes, targets, camera, lodSettings(d.precision), view);
  out.image.resize(targets.pixels());
  gpu::readBuffer(context, targets.image, 0, out.image.data(), out.image.size() * 4);
  if (!d.hqs) {
    out.words.resize(targets.pixels());
    gpu::readBuffer(context, targets.words, 0, out.words.data(), out.words.size() * 8);
  }
  return out;
}

struct Reference {
  std::vector<uint64_t> words;
  std::vector<uint32_t> image;
};

Reference drawBruteForce(gpu::Context& context, const PointCloud& cloud, const Camera& camera, uint32_t w,
                         uint32_t h, Method method) {
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(context, cloud, upload);
  Renderer renderer(context, w, h);
  RenderSettings s;
  s.method = method;
  s.captureWords = methodInfo(method).closest;
  s.background = 0;
  renderer.render(scene, camera, s);
  Reference r;
  if (s.captureWords) r.words = renderer.framebufferWords();
  r.image = renderer.image();
  return r;
}

// With POINTRAST_TEST_PNG set to a folder, the test's images are written there to be looked at.
void savePng(const std::string& name, uint32_t w, uint32_t h, const std::vector<uint32_t>& image) {
  const char* dir = std::getenv("POINTRAST_TEST_PNG");
  if (!dir || !*dir) return;
  std::string file = name;
  std::replace(file.begin(), file.end(), ' ', '-');
  std::replace(file.begin(), file.end(), '/', '_');
  io::writePng(std::string(dir) + "/" + file + ".png", w, h, image.data());
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

int maxChannelDiff(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b,
                   double* withinOne = nullptr) {
  int worst = 0;
  size_t ok = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    int pixel = 0;
    for (int c = 0; c < 4; ++c)
      pixel = std::max(pixel, std::abs(int((a[i] >> (8 * c)) & 0xFF) - int((b[i] >> (8 * c)) & 0xFF)));
    worst = std::max(worst, pixel);
    ok += pixel <= 1;
  }
  if (withinOne) *withinOne = a.empty() ? 1.0 : double(ok) / double(a.size());
  return worst;
}

// A random box, generated terrain and a TLS scan, each as an in-memory octree whose colors name points.
std::vector<std::pair<std::string, PointCloud>> testClouds() {
  std::vector<std::pair<std::string, PointCloud>> clouds;
  std::mt19937_64 rng(14);
  clouds.emplace_back("random", randomBoxCloud(rng, 60'000, {20, 10, 5}));
  GenerateOptions options;
  options.points = 80'000;
  options.progress = false;
  clouds.emplace_back("terrain", generateScene(Scene::Terrain, options));
  options.points = 60'000;
  clouds.emplace_back("tls", generateScene(Scene::Tls, options));
  return clouds;
}

std::vector<std::pair<std::string, Camera>> views(const Bounds& bounds, double aspect) {
  Camera inside;
  inside.eye = bounds.center() + 0.1 * (bounds.max - bounds.center());
  inside.target = bounds.max;
  Camera close;
  close.eye = bounds.center();
  close.target = bounds.center() + glm::dvec3(1, 0, 0);
  return {{"overview", overviewCamera(bounds, aspect)}, {"inside", inside}, {"close", close}};
}

uint64_t octreeBytes(const MemoryOctree& tree) {
  uint64_t pages = 0;
  for (const auto& [key, records] : tree.nodes)
    pages += lod::pagesOf(records.size());
  return pages * shared::kLodPageBytes;
}

} // namespace

TEST(LodLayout, ShadersMatchTheSharedStructs) {
  for (const char* name : {"lod_nodes.comp", "raster_lod.comp", "raster_lod_hqs.comp"}) {
    gpu::SpirvReflection r = gpu::reflectSpirv(gpu::findShader(name));
    EXPECT_EQ(r.pushConstantSize, sizeof(shared::LodPush)) << name;
    EXPECT_EQ(r.localSize[0] * r.localSize[1] * r.localSize[2], shared::kPointGroupSize) << name;
  }
  EXPECT_EQ(gpu::reflectSpirv(gpu::findShader("resolve_lod.comp")).pushConstantSize,
            sizeof(shared::ResolvePush));
}

TEST_F(GpuTest, LodDrawsEveryPointAndMatchesAtomicMin) {
  const uint32_t w = 200, h = 120;
  for (auto& [name, cloud] : testClouds()) {
    MemoryOctree tree;
    buildOctree(tree, cloud);
    tree.colorsAreIndices();
    ASSERT_GT(tree.nodes.size(), 8u) << name;
    const PointCloud all = tree.cloud();
    for (auto& [viewName, camera] : views(all.bounds, double(w) / h)) {
      const std::string where = name + " / " + viewName;
      Reference reference = drawBruteForce(*context, all, camera, w, h, Method::AtomicMin);
      LodDrawn lod = drawOctree(*context, tree, camera, w, h, {false, 3});
      savePng("lod " + where, w, h, lod.image);
      savePng("atomicmin " + where, w, h, reference.image);
      EXPECT_GT(litCount(reference.image), 100u) << where;
      // Colors name points: an equal pixel means the same point won (the depth bits may differ by an ulp, the
      // position being decoded from its node's 30-bit quantization, as the batch methods' are).
      const double same = equalLitFraction(lod.image, reference.image);
      EXPECT_GE(same, 0.999) << where;
      if (same < 1.0) std::printf("%s: %.4f %% of lit pixels equal\n", where.c_str(), 100 * same);
      const lod::LodStats& s = lod.result.lod;
      if (viewName == "overview") {
        EXPECT_EQ(s.nodesSelected, tree.nodes.size()) << where << ": every node, with no LOD culling";
        EXPECT_EQ(s.pointsSelected, all.size()) << where;
      }
      EXPECT_EQ(s.pointsDrawn, s.pointsSelected) << where;
      EXPECT_EQ(lod.result.passes, 1u) << where;
      ASSERT_TRUE(lod.result.frame.batch) << where;
      const BatchStats& b = *lod.result.frame.batch;
      EXPECT_EQ(b.batchesProcessed, s.nodesDrawn) << where;
      EXPECT_EQ(b.pointsByWords[2], b.pointsProcessed) << where << ": precision forced to 3 words";
      EXPECT_GE(b.pointsRendered, litCount(lod.image)) << where;
    }
  }
}

TEST_F(GpuTest, LodHqsMatchesHqs) {
  const uint32_t w = 160, h = 100;
  for (auto& [name, cloud] : testClouds()) {
    MemoryOctree tree;
    buildOctree(tree, cloud);
    const PointCloud all = tree.cloud();
    const Camera camera = overviewCamera(all.bounds, double(w) / h);
    Reference hqs = drawBruteForce(*context, all, camera, w, h, Method::Hqs);
    LodDrawn lod = drawOctree(*context, tree, camera, w, h, {true, 3});
    savePng("lod-hqs " + name, w, h, lod.image);
    savePng("hqs " + name, w, h, hqs.image);
    EXPECT_TRUE(lod.words.empty());
    double withinOne = 0;
    maxChannelDiff(lod.image, hqs.image, &withinOne);
    // As batch-hqs against hqs: points on pixel borders may switch pixels after quantization.
    EXPECT_GE(withinOne, 0.998) << name;
    ASSERT_TRUE(lod.result.frame.batch);
    EXPECT_GT(lod.result.frame.batch->pointsBlended, litCount(lod.image)) << name;
  }
}

TEST_F(GpuTest, LodWithATenthOfTheOctreeInGpuMemoryIsBitIdentical) {
  const uint32_t w = 160, h = 100;
  for (auto& [name, cloud] : testClouds()) {
    MemoryOctree tree;
    buildOctree(tree, cloud, 1000);
    tree.colorsAreIndices();
    const uint64_t tenth = octreeBytes(tree) / 10;
    const PointCloud all = tree.cloud();
    for (auto& [viewName, camera] : views(all.bounds, double(w) / h)) {
      const std::string where = name + " / " + viewName;
      for (uint32_t precision : {0u, 3u}) {
        LodDrawn whole = drawOctree(*context, tree, camera, w, h, {false, precision});
        LodDrawn parts = drawOctree(*context, tree, camera, w, h, {false, precision, 0, 0, tenth});
        EXPECT_EQ(whole.result.passes, 1u) << where;
        if (viewName == "overview") {
          EXPECT_GE(parts.result.passes, 10u) << where;
        }
        EXPECT_LE(parts.result.lod.residentBytes, tenth) << where;
        EXPECT_EQ(parts.words, whole.words) << where << ", precision " << precision;
        EXPECT_EQ(parts.image, whole.image) << where << ", precision " << precision;
        EXPECT_EQ(parts.result.frame.batch->pointsProcessed, whole.result.frame.batch->pointsProcessed)
            << where;
      }
      LodDrawn wholeHqs = drawOctree(*context, tree, camera, w, h, {true, 0});
      LodDrawn partsHqs = drawOctree(*context, tree, camera, w, h, {true, 0, 0, 0, tenth});
      EXPECT_EQ(partsHqs.image, wholeHqs.image) << where << ", lod-hqs";
      EXPECT_EQ(partsHqs.result.frame.batch->pointsBlended, wholeHqs.result.frame.batch->pointsBlended)
          << where;
    }
  }
}

} // namespace pointrast::test

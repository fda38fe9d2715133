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
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <thread>

#include <sys/resource.h>
#include <unistd.h>

#include "base/error.h"
#include "cloud/generate.h"
#include "gpu/buffer.h"
#include "gpu/shader_registry.h"
#include "gpu/shared_types.h"
#include "gpu/spirv_reflect.h"
#include "gpu_fixture.h"
#include "io/format_table.h"
#include "io/potree/potree.h"
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
  FrameStats stats;
  const lod::LodStats& lod() const { return *stats.lod; }
  const BatchStats& gpu() const { return *stats.batch; }
};

lod::LodOptions smallOptions(uint64_t gpuBytes) {
  lod::LodOptions o;
  o.gpuBytes = gpuBytes;
  o.readers = 2;
  o.stagingBytes = 8ull << 20;
  return o;
}

RenderSettings lodSettings(const LodDraw& d) {
  RenderSettings s;
  s.method = d.hqs ? pointMethod("lod-hqs") : pointMethod("lod");
  s.precision = d.precision;
  s.minNodePx = d.minNodePx;
  s.pointBudget = d.pointBudget;
  s.captureWords = !d.hqs;
  s.background = 0;
  s.frames = 1;
  s.warmup = 0;
  return s;
}

LodDrawn drawOctree(gpu::Context& context, lod::NodeSource& source, const Camera& camera, uint32_t w,
                    uint32_t h, const LodDraw& d) {
  Renderer renderer(context, w, h);
  lod::LodScene scene(context, source, smallOptions(d.gpuBytes));
  LodDrawn out;
  out.stats = renderer.render(scene, camera, lodSettings(d));
  EXPECT_TRUE(out.stats.lod && out.stats.batch);
  out.image = renderer.image();
  if (!d.hqs) out.words = renderer.framebufferWords();
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
  s.captureWords = hasCanonicalWords(methodInfo(method));
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
      Reference reference = drawBruteForce(*context, all, camera, w, h, pointMethod("atomicmin"));
      LodDrawn lod = drawOctree(*context, tree, camera, w, h, {false, 3});
      savePng("lod " + where, w, h, lod.image);
      savePng("atomicmin " + where, w, h, reference.image);
      EXPECT_GT(litCount(reference.image), 100u) << where;
      // Colors name points: an equal pixel means the same point won (the depth bits may differ by an ulp, the
      // position being decoded from its node's 30-bit quantization, as the batch methods' are).
      const double same = equalLitFraction(lod.image, reference.image);
      EXPECT_GE(same, 0.999) << where;
      if (same < 1.0) std::printf("%s: %.4f %% of lit pixels equal\n", where.c_str(), 100 * same);
      const lod::LodStats& s = lod.lod();
      if (viewName == "overview") {
        EXPECT_EQ(s.nodesSelected, tree.nodes.size()) << where << ": every node, with no LOD culling";
        EXPECT_EQ(s.pointsSelected, all.size()) << where;
      }
      EXPECT_EQ(s.pointsDrawn, s.pointsSelected) << where;
      EXPECT_EQ(lod.lod().passes, 1u) << where;
      const BatchStats& b = lod.gpu();
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
    Reference hqs = drawBruteForce(*context, all, camera, w, h, pointMethod("hqs"));
    LodDrawn lod = drawOctree(*context, tree, camera, w, h, {true, 3});
    savePng("lod-hqs " + name, w, h, lod.image);
    savePng("hqs " + name, w, h, hqs.image);
    EXPECT_TRUE(lod.words.empty());
    double withinOne = 0;
    maxChannelDiff(lod.image, hqs.image, &withinOne);
    // As batch-hqs against hqs: points on pixel borders may switch pixels after quantization.
    EXPECT_GE(withinOne, 0.998) << name;
    EXPECT_GT(lod.gpu().pointsBlended, litCount(lod.image)) << name;
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
      for (uint32_t precision :
           viewName == "overview" ? std::vector<uint32_t>{0, 3} : std::vector<uint32_t>{0}) {
        LodDrawn whole = drawOctree(*context, tree, camera, w, h, {false, precision});
        LodDrawn parts = drawOctree(*context, tree, camera, w, h, {false, precision, 0, 0, tenth});
        EXPECT_EQ(whole.lod().passes, 1u) << where;
        if (viewName == "overview") {
          EXPECT_GE(parts.lod().passes, 10u) << where;
        }
        EXPECT_LE(parts.lod().residentBytes, tenth) << where;
        EXPECT_EQ(parts.words, whole.words) << where << ", precision " << precision;
        EXPECT_EQ(parts.image, whole.image) << where << ", precision " << precision;
        EXPECT_EQ(parts.gpu().pointsProcessed, whole.gpu().pointsProcessed) << where;
      }
      LodDrawn wholeHqs = drawOctree(*context, tree, camera, w, h, {true, 0});
      LodDrawn partsHqs = drawOctree(*context, tree, camera, w, h, {true, 0, 0, 0, tenth});
      EXPECT_EQ(partsHqs.image, wholeHqs.image) << where << ", lod-hqs";
      EXPECT_EQ(partsHqs.gpu().pointsBlended, wholeHqs.gpu().pointsBlended) << where;
    }
  }
}

} // namespace pointrast::test

namespace pointrast::test {

namespace {

// The hand-built octree of the exact-statistics tests, seen by axisCamera() (eye at the origin looking down
// -z, 90 degrees) in a 64 x 64 image. Root cube [-16, 16]^3; each node's points sit at pixel centres, one
// point a pixel, inside the node's cube:
//   r       100 points anywhere in view                             projected size: eye inside, infinite
//   r0      200 points, cube [-16, 0]^3 (lower left of the image)    eye on its sphere: infinite
//   r6      300 points, cube [0, 16]^2 x [-16, 0] (upper right)      infinite
//   r1      400 points, cube [-16, 0]^2 x [0, 16], whose corner is the eye, all behind the eye: taken by the
//           CPU (its cube reaches into the frustum), culled on the GPU (its points' bounds do not);
//           projected size infinite. Its child r12 (10 points, [-16, -8] x [-8, 0] x [0, 8]) is culled on
//           the CPU and never read.
//   r61      50 points, cube [0, 8]^2 x [-8, 0]                      infinite
//   r64      60 points, cube [8, 16] x [0, 8] x [-16, -8]            12.7 pixels
//   r65      70 points, cube [8, 16] x [0, 8] x [-8, 0], all outside the image (x > -z): culled on the GPU
//                                                                    16.7 pixels
constexpr uint32_t kHandSize = 64;

struct HandTree {
  MemoryOctree tree;
  std::map<std::string, uint32_t> colorOf; // one color per node
};

void handBuiltOctree(HandTree& hand) {
  MemoryOctree& tree = hand.tree;
  tree.meta.source = "hand-built octree";
  tree.meta.scale = glm::dvec3(1e-5);
  tree.meta.cube.min = glm::dvec3(-16);
  tree.meta.cube.max = glm::dvec3(16);
  tree.meta.spacing = 0.25;
  tree.meta.fields.color = true;
  tree.meta.fields.colorMax = 255;
  std::set<uint32_t> used;
  auto add = [&](const std::string& name, int count, uint32_t color, bool onScreen) {
    lod::NodeKey key;
    for (size_t i = 1; i < name.size(); ++i)
      key = key.child(name[i] - '0');
    const Bounds cube = tree.meta.nodeCube(key);
    std::vector<PointRecord>& records = tree.nodes[key];
    hand.colorOf[name] = color;
    auto record = [&](glm::dvec3 p) {
      PointRecord r;
      r.x = int32_t(std::llround(p.x / 1e-5));
      r.y = int32_t(std::llround(p.y / 1e-5));
      r.z = int32_t(std::llround(p.z / 1e-5));
      r.rgb[0] = uint16_t(color & 0xFF);
      r.rgb[1] = uint16_t((color >> 8) & 0xFF);
      r.rgb[2] = uint16_t((color >> 16) & 0xFF);
      records.push_back(r);
    };
    if (!onScreen) { // outside the image or behind the eye, inside the cube
      for (int i = 0; i < count; ++i)
        record(cube.min + (cube.max - cube.min) * glm::dvec3(0.8, 0.3 + 0.4 * i / count, 0.6));
      return;
    }
    for (uint32_t pixel = 0; pixel < kHandSize * kHandSize && int(records.size()) < count; ++pixel) {
      if (used.count(pixel)) continue;
      const double sx = (pixel % kHandSize + 0.5) / (kHandSize / 2.0) - 1.0;
      const double sy = 1.0 - (pixel / kHandSize + 0.5) / (kHandSize / 2.0);
      for (double depth = 0.5; depth < 16; depth += 0.25) {
        const glm::dvec3 p{sx * depth, sy * depth, -depth};
        if (glm::all(glm::greaterThan(p, cube.min + 0.01)) && glm::all(glm::lessThan(p, cube.max - 0.01))) {
          record(p);
          used.insert(pixel);
          break;
        }
      }
    }
  };
  add("r", 100, 0x000001, true);
  add("r0", 200, 0x000002, true);
  add("r6", 300, 0x000003, true);
  add("r1", 400, 0x000004, false);
  add("r12", 10, 0x000005, false);
  add("r61", 50, 0x000006, true);
  add("r64", 60, 0x000007, true);
  add("r65", 70, 0x000008, false);
  Bounds all;
  for (const auto& [key, records] : tree.nodes)
    for (const PointRecord& r : records)
      all.expand(glm::dvec3(r.x, r.y, r.z) * 1e-5);
  tree.meta.bounds = all;
  for (const auto& [key, records] : tree.nodes)
    tree.meta.pointCount += records.size();
}

std::map<uint32_t, size_t> colorCounts(const std::vector<uint32_t>& image) {
  std::map<uint32_t, size_t> counts;
  for (uint32_t c : image)
    if (c) ++counts[c & 0xFFFFFF];
  return counts;
}

} // namespace

TEST_F(GpuTest, LodStatisticsAreExactOnAHandBuiltOctree) {
  HandTree hand;
  handBuiltOctree(hand);
  for (const auto& [name, size] :
       std::map<std::string, size_t>{{"r", 100}, {"r0", 200}, {"r6", 300}, {"r61", 50}, {"r64", 60}}) {
    lod::NodeKey key;
    for (size_t i = 1; i < name.size(); ++i)
      key = key.child(name[i] - '0');
    ASSERT_EQ(hand.tree.nodes[key].size(), size)
        << name << ": the test's placement found room for every point";
  }
  struct Case {
    double minNodePx;
    uint64_t budget;
    uint64_t nodes, points;           // selected
    uint64_t processed, rendered;     // nodes on the GPU: drawn, not culled
    uint64_t pointsProcessed, pixels; // points of rendered nodes; lit pixels (one point each)
  };
  const Case cases[] = {
      // Taken in the order r, r0, r1, r6 (infinite sizes, key order), r61, r65, r64; r1 and r65 culled on the
      // GPU.
      {0, 0, 7, 1180, 7, 5, 710, 710},    {14, 0, 6, 1120, 6, 4, 650, 650}, // r64 (12.7 px) LOD-culled
      {20, 0, 5, 1050, 5, 4, 650, 650},                                     // r65 (16.7 px) too
      {0, 1050, 5, 1050, 5, 4, 650, 650},                                   // the budget stops before r65
      {0, 1049, 4, 1000, 4, 3, 600, 600},                                   // ... before r61
  };
  for (bool hqs : {false, true}) {
    for (const Case& c : cases) {
      const std::string where = std::string(hqs ? "lod-hqs" : "lod") + ", min-node-px " +
                                std::to_string(c.minNodePx) + ", budget " + std::to_string(c.budget);
      LodDrawn d = drawOctree(*context, hand.tree, axisCamera(), kHandSize, kHandSize,
                              {hqs, 0, c.minNodePx, c.budget});
      const lod::LodStats& s = d.lod();
      EXPECT_EQ(s.nodesSelected, c.nodes) << where;
      EXPECT_EQ(s.pointsSelected, c.points) << where;
      EXPECT_EQ(s.nodesDrawn, c.processed) << where;
      const BatchStats& b = d.gpu();
      EXPECT_EQ(b.batchesProcessed, c.processed) << where;
      EXPECT_EQ(b.batchesRendered, c.rendered) << where;
      EXPECT_EQ(b.pointsProcessed, c.pointsProcessed) << where;
      EXPECT_EQ(b.pointsRendered, c.pixels) << where;
      EXPECT_EQ(b.pointsBlended, hqs ? c.pixels : 0u) << where;
      EXPECT_EQ(litCount(d.image), c.pixels) << where;
      // Nodes outside the view frustum are never drawn: no pixel has their colors.
      const std::map<uint32_t, size_t> counts = colorCounts(d.image);
      for (const char* outside : {"r1", "r12", "r65"})
        EXPECT_EQ(counts.count(hand.colorOf[outside]), 0u) << where << ": " << outside;
      // What was streamed: the selected nodes, not r1 and its subtree.
      EXPECT_EQ(s.nodesLoaded, c.nodes) << where;
      EXPECT_EQ(s.bytesStreamed, 24 * c.points) << where;
    }
  }
  EXPECT_EQ(hand.tree.info({}).childMask, 0b01000011);
}

} // namespace pointrast::test

namespace pointrast::test {

namespace {

// A viewer's frame loop: Renderer::renderFrame, one frame at a time.
class FrameLoop {
public:
  FrameLoop(gpu::Context& context, lod::NodeSource& source, uint32_t w, uint32_t h,
            const lod::LodOptions& options)
      : renderer_(context, w, h), scene_(context, source, options) {}

  // One frame; returns whether the scene said it changed.
  bool frame(const Camera& camera, const lod::LodView& view) {
    LodDraw d;
    d.minNodePx = view.minNodePx;
    d.pointBudget = view.pointBudget;
    last_ = renderer_.renderFrame(scene_, camera, lodSettings(d));
    return last_.lod->changed;
  }
  // Frames until converged (at most `limit`), pausing briefly between them as a display would.
  uint32_t converge(const Camera& camera, const lod::LodView& view, uint32_t limit = 3000) {
    for (uint32_t n = 1; n <= limit; ++n) {
      frame(camera, view);
      if (last_.lod->converged) return n;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return 0;
  }
  std::vector<uint64_t> words() { return renderer_.framebufferWords(); }
  std::vector<uint32_t> image() { return renderer_.image(); }
  lod::LodScene& scene() { return scene_; }
  const FrameStats& last() const { return last_; }

private:
  Renderer renderer_;
  lod::LodScene scene_;
  FrameStats last_;
};

} // namespace

TEST_F(GpuTest, LodFramesRefineFromResidentAncestorsToTheFullImage) {
  const uint32_t w = 160, h = 100;
  GenerateOptions options;
  options.points = 100'000;
  options.progress = false;
  MemoryOctree tree;
  buildOctree(tree, generateScene(Scene::Terrain, options), 1000);
  const Camera camera = overviewCamera(tree.meta.bounds, double(w) / h);
  const lod::LodView view{0, 0};
  LodDrawn offline = drawOctree(*context, tree, camera, w, h, {false, 0});

  lod::LodOptions slow = smallOptions(64ull << 20);
  slow.uploadBytesPerFrame = 2 * shared::kLodPageBytes; // a node or two a frame: many partial frames
  FrameLoop loop(*context, tree, w, h, slow);
  uint64_t drawnBefore = 0;
  uint32_t frames = 0, partial = 0;
  for (; frames < 3000 && !loop.scene().converged(); ++frames) {
    const bool changed = loop.frame(camera, view);
    const lod::LodStats& s = loop.scene().stats();
    // A fixed camera only adds nodes: the frame changed exactly when it drew more points (or is the first).
    EXPECT_EQ(changed, frames == 0 || s.pointsDrawn != drawnBefore) << "frame " << frames;
    EXPECT_GE(s.pointsDrawn, drawnBefore) << "frame " << frames << ": a fixed camera only refines";
    EXPECT_LE(s.pointsDrawn, s.pointsSelected);
    drawnBefore = s.pointsDrawn;
    if (s.pointsDrawn > 0 && s.pointsDrawn < s.pointsSelected) {
      ++partial;
      if (partial == 3) savePng("lod refining", w, h, loop.image());
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(loop.scene().converged()) << "not converged after " << frames << " frames";
  EXPECT_GT(partial, 3u) << "the frames before convergence drew resident ancestors";
  EXPECT_EQ(loop.words(), offline.words);
  EXPECT_EQ(loop.image(), offline.image);
  // Converged, same camera: nothing changed, nothing to draw again.
  EXPECT_FALSE(loop.frame(camera, view));
  EXPECT_FALSE(loop.frame(camera, view));
  Camera moved = camera;
  moved.eye.z += 1.0;
  EXPECT_TRUE(loop.frame(moved, view));
}

namespace {
// The niceness of each thread of this process (the 19th field of /proc/self/task/TID/stat).
std::vector<int> threadNiceness() {
  std::vector<int> out;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::FILE* f = std::fopen((task.path() / "stat").c_str(), "r");
    if (!f) continue;
    char line[1024] = {};
    const size_t n = std::fread(line, 1, sizeof line - 1, f);
    std::fclose(f);
    const char* p = std::strrchr(line, ')'); // the command name may hold spaces
    if (!p || n == 0) continue;
    int field = 2, nice = 0;
    for (const char* c = p + 1; *c; ++c)
      if (*c == ' ' && ++field == 19) {
        nice = std::atoi(c + 1);
        break;
      }
    out.push_back(nice);
  }
  return out;
}
} // namespace

// A viewer's readers run below the frame's threads: LodOptions::readerNiceness lowers exactly the reader
// threads' priority (the calling thread keeps its own).
TEST_F(GpuTest, LodReadersRunAtTheNicenessAskedFor) {
  GenerateOptions options;
  options.points = 20'000;
  options.progress = false;
  MemoryOctree tree;
  buildOctree(tree, generateScene(Scene::Terrain, options), 1000);
  auto countNice = [](int value) {
    const std::vector<int> all = threadNiceness();
    return std::count(all.begin(), all.end(), value);
  };
  const int own = getpriority(PRIO_PROCESS, 0);
  ASSERT_LT(own, 9) << "the test runs at niceness " << own << " already";
  const int lowered = own + 10 > 19 ? 19 : own + 10;
  const auto before = countNice(lowered);
  lod::LodOptions o = smallOptions(64ull << 20);
  o.readers = 3;
  o.readerNiceness = 10;
  lod::LodScene scene(*context, tree, o);
  // The readers set their niceness as they start: wait for all three, bounded.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (countNice(lowered) < before + 3 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::yield();
  EXPECT_EQ(countNice(lowered), before + 3);
  EXPECT_EQ(getpriority(PRIO_PROCESS, 0), own) << "the calling thread keeps its priority";
}

TEST_F(GpuTest, LodCacheEvictsAcrossCameraJumpsAndConvergesEachTime) {
  const uint32_t w = 160, h = 100;
  GenerateOptions options;
  options.points = 150'000;
  options.progress = false;
  MemoryOctree tree;
  buildOctree(tree, generateScene(Scene::Terrain, options), 1000);
  tree.colorsAreIndices();
  const uint64_t quarter = octreeBytes(tree) / 4; // the union of the views' selections is larger
  const Bounds& b = tree.meta.bounds;
  const lod::LodView view{15, 0};
  FrameLoop loop(*context, tree, w, h, smallOptions(quarter));
  for (int jump = 0; jump < 6; ++jump) {
    // Low views over the terrain's four quarters, then the overview.
    Camera camera = overviewCamera(b, double(w) / h);
    if (jump < 4) {
      const glm::dvec3 size = b.size();
      camera.target = b.min + size * glm::dvec3(jump % 2 ? 0.75 : 0.25, jump / 2 ? 0.75 : 0.25, 0.3);
      camera.eye = camera.target + glm::dvec3(-0.1 * size.x, -0.1 * size.y, 0.1 * size.x);
    }
    const std::string where = "jump " + std::to_string(jump);
    const uint32_t frames = loop.converge(camera, view);
    ASSERT_GT(frames, 0u) << where << ": not converged";
    const lod::LodStats& s = loop.scene().stats();
    EXPECT_LE(s.residentBytes, quarter) << where;
    EXPECT_FALSE(s.budgetReached) << where << ": the view's selection fits the cache";
    LodDrawn offline = drawOctree(*context, tree, camera, w, h, {false, 0, view.minNodePx});
    EXPECT_EQ(loop.image(), offline.image) << where;
    savePng("lod jump " + std::to_string(jump), w, h, loop.image());
  }
  EXPECT_GT(loop.scene().stats().nodesEvicted, 0u);
}

} // namespace pointrast::test

namespace pointrast::test {

namespace {

// An octree whose hierarchy lies about a node's children.
class LyingOctree : public MemoryOctree {
public:
  lod::NodeKey liar;
  std::vector<lod::NodeInfo> children(const lod::NodeInfo& node) override {
    std::vector<lod::NodeInfo> kids = MemoryOctree::children(node);
    if (node.key == liar && !kids.empty()) kids.front().key = kids.front().key.child(0); // a grandchild
    return kids;
  }
};

// An octree that returns fewer points than its hierarchy claims for one node.
class ShortOctree : public MemoryOctree {
public:
  lod::NodeKey shortNode;
  std::vector<PointRecord> readNode(const lod::NodeInfo& node) override {
    std::vector<PointRecord> records = MemoryOctree::readNode(node);
    if (node.key == shortNode) records.resize(records.size() / 2);
    return records;
  }
};

void buildTestOctree(MemoryOctree& tree) {
  GenerateOptions options;
  options.points = 40'000;
  options.progress = false;
  buildOctree(tree, generateScene(Scene::Terrain, options), 1000);
}

// The deepest node of a tree (a leaf the full selection reaches last).
lod::NodeKey deepest(const MemoryOctree& tree) {
  lod::NodeKey deep;
  for (const auto& [key, records] : tree.nodes)
    if (key.level >= deep.level) deep = key;
  return deep;
}

template <class Run> std::string errorOf(Run&& run) {
  try {
    run();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

} // namespace

TEST_F(GpuTest, LodDamagedNodeWhileStreamingIsOneClearError) {
  const uint32_t w = 96, h = 64;
  MemoryOctree tree;
  buildTestOctree(tree);
  const lod::NodeKey bad = deepest(tree);
  ASSERT_GT(bad.level, 1);
  tree.damagedPoints.insert(bad);
  const Camera camera = overviewCamera(tree.meta.bounds, double(w) / h);
  for (bool hqs : {false, true}) {
    for (uint64_t budget : {uint64_t(64) << 20, octreeBytes(tree) / 10}) { // one pass, several passes
      const std::string message = errorOf([&] {
        drawOctree(*context, tree, camera, w, h, {hqs, 0, 0, 0, budget});
      });
      EXPECT_NE(message.find("memory octree: node " + bad.potreeName() + " ends past the end of octree.bin"),
                std::string::npos)
          << message;
    }
  }
  // Frame by frame: frames go on until the reader meets the node; then update() throws that error.
  FrameLoop loop(*context, tree, w, h, smallOptions(64ull << 20));
  const std::string message = errorOf([&] { loop.converge(camera, {0, 0}); });
  EXPECT_NE(message.find("node " + bad.potreeName() + " ends past the end"), std::string::npos) << message;
}

TEST_F(GpuTest, LodDamagedHierarchyIsOneClearError) {
  const uint32_t w = 96, h = 64;
  {
    MemoryOctree tree;
    buildTestOctree(tree);
    const lod::NodeKey bad = deepest(tree).parent();
    tree.damagedChildren.insert(bad);
    const Camera camera = overviewCamera(tree.meta.bounds, double(w) / h);
    const std::string message = errorOf([&] { drawOctree(*context, tree, camera, w, h, {}); });
    EXPECT_NE(message.find("the hierarchy below node " + bad.potreeName() + " is truncated"),
              std::string::npos)
        << message;
  }
  {
    LyingOctree tree;
    buildTestOctree(tree);
    tree.liar = lod::NodeKey{}.child(0);
    while (!tree.nodes.count(tree.liar))
      tree.liar = tree.liar.parent().child(tree.liar.childIndex() + 1);
    const Camera camera = overviewCamera(tree.meta.bounds, double(w) / h);
    const std::string message = errorOf([&] { drawOctree(*context, tree, camera, w, h, {}); });
    EXPECT_NE(message.find("memory octree: node "), std::string::npos) << message;
    EXPECT_NE(message.find("is not one of its eight"), std::string::npos) << message;
  }
  {
    ShortOctree tree;
    buildTestOctree(tree);
    tree.shortNode = deepest(tree);
    const Camera camera = overviewCamera(tree.meta.bounds, double(w) / h);
    const std::string message = errorOf([&] { drawOctree(*context, tree, camera, w, h, {}); });
    EXPECT_NE(message.find("node " + tree.shortNode.potreeName() + " of memory octree holds"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("points where its hierarchy says"), std::string::npos) << message;
  }
}

TEST_F(GpuTest, LodNodeLargerThanTheCacheIsAClearError) {
  MemoryOctree tree;
  buildTestOctree(tree);
  const Camera camera = overviewCamera(tree.meta.bounds, 1.5);
  try {
    drawOctree(*context, tree, camera, 96, 64, {false, 0, 0, 0, shared::kLodPageBytes / 2});
    ADD_FAILURE() << "no error for a cache without a page";
  } catch (const UnsupportedError& e) {
    EXPECT_NE(std::string(e.what()).find("holds no page"), std::string::npos) << e.what();
  }
  // The root alone (all it selects from far away) fits one page; a cache of one page draws the root in one
  // pass, and a full selection in as many passes as it has nodes.
  LodDrawn one = drawOctree(*context, tree, camera, 96, 64, {false, 0, 0, 0, shared::kLodPageBytes});
  EXPECT_EQ(one.lod().passes, one.lod().nodesSelected);
  // A node of two pages in a cache of one.
  MemoryOctree big;
  std::mt19937_64 rng(3);
  buildOctree(big, randomBoxCloud(rng, shared::kLodPagePoints + 1, {1, 1, 1}), shared::kLodPagePoints + 1);
  ASSERT_EQ(big.nodes.size(), 1u);
  try {
    drawOctree(*context, big, overviewCamera(big.meta.bounds, 1.5), 96, 64,
               {false, 0, 0, 0, shared::kLodPageBytes});
    ADD_FAILURE() << "no error for a node larger than the cache";
  } catch (const UnsupportedError& e) {
    EXPECT_NE(
        std::string(e.what()).find("node r of memory octree needs 128 KiB of GPU memory, more than the node "
                                   "cache's budget of 64 KiB"),
        std::string::npos)
        << e.what();
  }
}

} // namespace pointrast::test

namespace pointrast::test {

TEST_F(GpuTest, LodStreamsAPotreeFolderAsItDrawsTheSameOctreeInMemory) {
  const uint32_t w = 160, h = 100;
  GenerateOptions options;
  options.points = 60'000;
  options.progress = false;
  MemoryOctree tree;
  buildOctree(tree, generateScene(Scene::Tls, options), 1500);
  const std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                    ("pointrast-lod-test-" + std::to_string(::getpid())) / "octree";
  std::filesystem::remove_all(dir.parent_path());
  std::filesystem::create_directories(dir.parent_path());
  {
    io::PotreeWriter writer(dir, tree.meta, {});
    for (const auto& [key, records] : tree.nodes)
      writer.writeNode(key, records.data(), records.size());
    writer.commit();
  }
  ASSERT_TRUE(io::detectFormat(dir) && io::detectFormat(dir)->openNodes);
  std::unique_ptr<lod::NodeSource> folder = io::openNodeSource(dir);
  const Camera camera = overviewCamera(tree.meta.bounds, double(w) / h);
  for (bool hqs : {false, true}) {
    for (uint64_t budget : {uint64_t(64) << 20, octreeBytes(tree) / 10}) {
      LodDrawn fromMemory = drawOctree(*context, tree, camera, w, h, {hqs, 0, 0, 0, budget});
      LodDrawn fromFolder = drawOctree(*context, *folder, camera, w, h, {hqs, 0, 0, 0, budget});
      EXPECT_EQ(fromFolder.image, fromMemory.image) << (hqs ? "lod-hqs" : "lod") << ", budget " << budget;
      EXPECT_EQ(fromFolder.words, fromMemory.words);
      EXPECT_EQ(fromFolder.lod().pointsDrawn, tree.points());
      EXPECT_GT(fromFolder.lod().bytesStreamed, 0u);
    }
  }
  if (const char* keep = std::getenv("POINTRAST_TEST_PNG"); keep && *keep)
    std::filesystem::copy(dir, std::filesystem::path(keep) / "octree",
                          std::filesystem::copy_options::recursive |
                              std::filesystem::copy_options::overwrite_existing);
  std::filesystem::remove_all(dir.parent_path());
  EXPECT_THROW(io::openNodeSource(dir), InputError);
}

} // namespace pointrast::test

namespace pointrast::test {

TEST_F(GpuTest, LodFullRenderAfterViewerFramesOnTheSameScene) {
  // Frames ask the readers for many nodes; a full render of the same scene right after must neither wait on
  // readers blocked by the small staging area nor draw anything but its own selection.
  const uint32_t w = 120, h = 80;
  MemoryOctree tree;
  GenerateOptions options;
  options.points = 60'000;
  options.progress = false;
  buildOctree(tree, generateScene(Scene::Terrain, options), 300);
  const Camera camera = overviewCamera(tree.meta.bounds, double(w) / h);
  lod::LodOptions small = smallOptions(64ull << 20);
  small.stagingBytes = 2 * shared::kLodPageBytes;
  Renderer renderer(*context, w, h);
  lod::LodScene scene(*context, tree, small);
  LodDraw d;
  RenderSettings settings = lodSettings(d);
  // The first frame knows the root only and asks for its children; the second asks for the points of the
  // level below, which fill the staging blocks while the deeper hierarchy is still unread.
  renderer.renderFrame(scene, camera, settings);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  renderer.renderFrame(scene, camera, settings);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const FrameStats full = renderer.render(scene, camera, settings);
  EXPECT_EQ(full.lod->pointsDrawn, tree.points());
  LodDrawn fresh = drawOctree(*context, tree, camera, w, h, d);
  EXPECT_EQ(renderer.image(), fresh.image);
}

} // namespace pointrast::test

namespace pointrast::test {

TEST_F(GpuTest, LodHqsMatchesHqsWithinOneEverywherePastThePackedWordsLimit) {
  // As batch-hqs against hqs: points near pixel centres at depths well within 1 % of the pixel's front
  // surface or 3 % behind it, and one pixel with 1,500 blended points (past the packed word's 255, so the
  // fallback sums are used), spread over the octree's nodes.
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
  const PointCloud cloud = cloudFromPoints(points, colors, 1e-7);
  MemoryOctree tree;
  buildOctree(tree, cloud, 2000);
  ASSERT_GT(tree.nodes.size(), 4u);
  const PointCloud all = tree.cloud();
  Reference hqs = drawBruteForce(*context, all, axisCamera(), W, H, pointMethod("hqs"));
  for (uint32_t precision : {3u, 0u})
    for (uint64_t budget : {uint64_t(64) << 20, octreeBytes(tree) / 10}) {
      LodDrawn lod = drawOctree(*context, tree, axisCamera(), W, H, {true, precision, 0, 0, budget});
      EXPECT_LE(maxChannelDiff(lod.image, hqs.image), 1)
          << "precision " << precision << ", budget " << budget;
      EXPECT_NE(lod.image[20 * W + 10], 0u);
    }
}

} // namespace pointrast::test

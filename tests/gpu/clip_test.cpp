// Clip volumes in the renderer (RenderSettings::filter, shaders/clip.inc.glsl):
// - a clip box, an oriented box and a polygon, kept inside or outside, give the framebuffer of rendering the
//   subset of points the rules keep (computed here on the CPU): the same framebuffer words for atomicmin, the
//   same image bit for bit for it, hqs, batch and batch-prefetch at full precision and hw-points;
// - batches and octree nodes whose boxes the clip keeps nothing of are culled and counted;
// - lod draws only kept points and agrees with atomicmin of the subset.
// Coordinates are multiples of 2^-12 and the subset keeps the whole cloud's bounds (its origin), so the float
// positions of both renders are the same numbers; clip boundaries lie half a grid step between points.
#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "gpu_fixture.h"
#include "lod_octree.h"
#include "render/clip_volumes.h"
#include "render/lod/lod_scene.h"
#include "render/renderer.h"

namespace pointrast::test {

namespace {

constexpr double kGrid = 1.0 / 4096;

// `count` points on the 2^-12 grid in [-1, 1]^3, sorted by x (so batches are slabs), random opaque colors.
PointCloud gridCloud(size_t count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> q(-4096, 4096);
  std::vector<glm::dvec3> points(count);
  for (glm::dvec3& p : points)
    p = glm::dvec3(q(rng), q(rng), q(rng)) * kGrid;
  std::sort(points.begin(), points.end(), [](const glm::dvec3& a, const glm::dvec3& b) { return a.x < b.x; });
  std::vector<uint32_t> colors(count);
  for (uint32_t& c : colors)
    c = 0xFF000000u | uint32_t(rng() & 0xFFFFFF);
  return cloudFromPoints(points, colors, kGrid);
}

glm::dvec3 worldOf(const PointCloud& cloud, size_t i) {
  return glm::dvec3(cloud.positions[3 * i], cloud.positions[3 * i + 1], cloud.positions[3 * i + 2]) *
             cloud.scale +
         cloud.offset;
}

// The rules of cloud/point_filter.h, written out independently of the renderer.
bool insideReference(const PointFilter& f, const glm::dvec3& p) {
  for (const ClipBox& b : f.boxes)
    if (glm::all(glm::lessThanEqual(b.min, p)) && glm::all(glm::lessThanEqual(p, b.max))) return true;
  for (const OrientedClipBox& b : f.orientedBoxes) {
    bool in = true;
    for (int k = 0; k < 3; ++k)
      in = in && std::abs(glm::dot(b.axes[k], p - b.center)) <= b.halfExtent[k];
    if (in) return true;
  }
  for (const ClipPolygon& poly : f.polygons) {
    if (p.z < poly.zMin || p.z > poly.zMax) continue;
    bool in = false;
    for (size_t i = 0, j = poly.vertices.size() - 1; i < poly.vertices.size(); j = i++) {
      const glm::dvec2 a = poly.vertices[j], b = poly.vertices[i];
      if ((b.y > p.y) != (a.y > p.y) && p.x < (a.x - b.x) * (p.y - b.y) / (a.y - b.y) + b.x) in = !in;
    }
    if (in) return true;
  }
  return false;
}

bool keptReference(const PointFilter& f, const glm::dvec3& p) {
  if (!f.hasClip() || f.clipMode == ClipMode::Highlight) return true;
  return insideReference(f, p) == (f.clipMode == ClipMode::Inside);
}

// The points the filter keeps, with the whole cloud's bounds (and so its origin).
PointCloud keptSubset(const PointCloud& cloud, const PointFilter& filter) {
  PointCloud sub;
  sub.scale = cloud.scale;
  sub.offset = cloud.offset;
  for (size_t i = 0; i < cloud.size(); ++i)
    if (keptReference(filter, worldOf(cloud, i))) {
      sub.positions.insert(sub.positions.end(), cloud.positions.begin() + 3 * i,
                           cloud.positions.begin() + 3 * i + 3);
      sub.colors.push_back(cloud.colors[i]);
    }
  sub.bounds = cloud.bounds;
  return sub;
}

Camera sideCamera() {
  Camera c;
  c.eye = {0.9, 1.3, 3.2};
  c.target = {0, 0, 0};
  c.up = {0, 1, 0};
  c.fovY = 60;
  c.nearW = 0.01;
  return c;
}

struct Drawn {
  std::vector<uint64_t> words;
  std::vector<uint32_t> image;
  FrameStats stats;
};

constexpr uint32_t kWidth = 160, kHeight = 120;

Drawn draw(gpu::Context& context, const PointCloud& cloud, const char* method, const PointFilter& filter) {
  RenderSettings s;
  s.method = parseMethod(method);
  s.captureWords = hasCanonicalWords(methodInfo(s.method));
  s.background = 0;
  s.precision = 3;
  s.filter = filter;
  UploadOptions upload;
  upload.progress = false;
  upload.layout = methodInfo(s.method).layout;
  GpuScene scene(context, cloud, upload);
  Renderer renderer(context, kWidth, kHeight);
  Drawn d;
  d.stats = renderer.render(scene, sideCamera(), s);
  d.image = renderer.image();
  if (s.captureWords) d.words = renderer.framebufferWords();
  return d;
}

size_t lit(const std::vector<uint32_t>& image) {
  return size_t(std::count_if(image.begin(), image.end(), [](uint32_t c) { return c != 0; }));
}

void expectSameAsSubset(gpu::Context& context, const PointCloud& cloud, const PointFilter& filter,
                        const std::string& what) {
  const PointCloud subset = keptSubset(cloud, filter);
  ASSERT_GT(subset.size(), cloud.size() / 20) << what;
  ASSERT_LT(subset.size(), cloud.size() - cloud.size() / 20) << what;
  for (const char* method : {"atomicmin", "hqs", "batch", "batch-prefetch", "hw-points"}) {
    const Drawn clipped = draw(context, cloud, method, filter);
    const Drawn reference = draw(context, subset, method, PointFilter{});
    EXPECT_GT(lit(reference.image), size_t(kWidth * kHeight / 20)) << what << ", " << method;
    size_t differ = 0;
    for (size_t i = 0; i < clipped.words.size() && i < reference.words.size(); ++i)
      differ += clipped.words[i] != reference.words[i];
    EXPECT_EQ(clipped.words.size(), reference.words.size()) << what << ", " << method;
    // The batch methods decode a point from its batch's quantization, and the subset's batches are others:
    // the depth may differ by an ulp, the winner (its unique color) may not.
    if (methodInfo(parseMethod(method)).layout == SceneLayout::Float) {
      EXPECT_EQ(differ, 0u) << what << ", " << method << ": framebuffer words differ";
    }
    differ = 0;
    for (size_t i = 0; i < clipped.image.size() && i < reference.image.size(); ++i)
      differ += clipped.image[i] != reference.image[i];
    EXPECT_EQ(differ, 0u) << what << ", " << method << ": pixels differ";
  }
}

PointFilter boxFilter(ClipMode mode) {
  PointFilter f;
  // Half a grid step off the points: no point lies on a face.
  const double h = kGrid / 2;
  f.boxes.push_back({{-0.5 + h, -0.7 + h, -1.5}, {0.25 + h, 0.4 + h, 0.3 + h}});
  f.boxes.push_back({{0.6 + h, -1.5, -1.5}, {1.5, 1.5, 1.5}});
  f.clipMode = mode;
  return f;
}

} // namespace

TEST_F(GpuTest, ClipBoxesDrawTheKeptSubset) {
  const PointCloud cloud = gridCloud(30000, 1);
  expectSameAsSubset(*context, cloud, boxFilter(ClipMode::Inside), "inside two boxes");
  expectSameAsSubset(*context, cloud, boxFilter(ClipMode::Outside), "outside two boxes");
}

TEST_F(GpuTest, ClipOrientedBoxesAndPolygonsDrawTheKeptSubset) {
  const PointCloud cloud = gridCloud(30000, 2);
  PointFilter f;
  OrientedClipBox box;
  const double a = 0.5; // radians about z
  box.center = {0.1, -0.2, 0.05};
  box.axes = {glm::dvec3(std::cos(a), std::sin(a), 0), glm::dvec3(-std::sin(a), std::cos(a), 0),
              glm::dvec3(0, 0, 1)};
  box.halfExtent = {0.5, 0.3, 0.6};
  f.orientedBoxes.push_back(box);
  ClipPolygon poly; // a concave "L" in x/y, z bounded below only
  poly.vertices = {{-0.9, 0.2}, {-0.2, 0.2}, {-0.2, 0.5}, {-0.6, 0.5}, {-0.6, 0.95}, {-0.9, 0.95}};
  poly.zMin = -0.4;
  f.polygons.push_back(poly);
  f.clipMode = ClipMode::Inside;
  expectSameAsSubset(*context, cloud, f, "inside an oriented box and a polygon");
  f.clipMode = ClipMode::Outside;
  expectSameAsSubset(*context, cloud, f, "outside an oriented box and a polygon");
}

TEST_F(GpuTest, ClipCullsBatchesOutsideAndCountsThem) {
  // 12 batches, slabs in x: the box keeps x in [-0.5, 0.25] (+ half a step), so batches wholly left or right
  // of it are culled by the clip; with Outside, batches wholly within are.
  const PointCloud cloud = gridCloud(12 * 10240, 3);
  PointFilter f;
  const double h = kGrid / 2;
  f.boxes.push_back({{-0.5 + h, -2, -2}, {0.25 + h, 2, 2}});
  for (ClipMode mode : {ClipMode::Inside, ClipMode::Outside}) {
    f.clipMode = mode;
    uint64_t outside = 0, straddling = 0;
    for (size_t b = 0; b < 12; ++b) {
      const double lo = worldOf(cloud, b * 10240).x, hi = worldOf(cloud, b * 10240 + 10239).x;
      const bool within = lo >= f.boxes[0].min.x && hi <= f.boxes[0].max.x;
      const bool disjoint = hi < f.boxes[0].min.x || lo > f.boxes[0].max.x;
      outside += mode == ClipMode::Inside ? disjoint : within;
      straddling += !within && !disjoint;
    }
    ASSERT_GE(outside, 3u);
    ASSERT_GE(straddling, 1u);
    // batch-hqs counts in its depth pass, as batch does; once is enough.
    for (const char* method : {"batch", mode == ClipMode::Inside ? "batch-hqs" : "batch-prefetch"}) {
      const Drawn d = draw(*context, cloud, method, f);
      ASSERT_TRUE(d.stats.batch) << method;
      const BatchStats& b = *d.stats.batch;
      EXPECT_EQ(b.batchesProcessed, 12u) << method;
      EXPECT_EQ(b.batchesClipped, outside) << method;
      EXPECT_EQ(b.batchesRendered, 12u - outside) << method << ": the camera sees every batch";
      EXPECT_EQ(b.pointsProcessed, (12u - outside) * 10240u) << method;
    }
  }
  const Drawn none = draw(*context, cloud, "batch", PointFilter{});
  EXPECT_EQ(none.stats.batch->batchesClipped, 0u);
  EXPECT_EQ(none.stats.batch->batchesRendered, 12u);
}

TEST_F(GpuTest, ClipInLodDrawsKeptPointsAndCullsNodes) {
  const PointCloud cloud = gridCloud(60000, 4);
  MemoryOctree tree;
  buildOctree(tree, cloud, 2000, 16);
  tree.colorsAreIndices();
  ASSERT_GT(tree.nodes.size(), 8u);
  PointFilter f = boxFilter(ClipMode::Inside);
  // The colors of the points each filter keeps (colors name points).
  std::set<uint32_t> keptColors;
  uint64_t nodesOutside = 0;
  for (const auto& [key, records] : tree.nodes) {
    Bounds box;
    for (const PointRecord& r : records) {
      const glm::dvec3 p = glm::dvec3(r.x, r.y, r.z) * tree.meta.scale + tree.meta.offset;
      box.expand(p);
      if (keptReference(f, p)) keptColors.insert(0xFF000000u | r.rgb[0] | r.rgb[1] << 8 | r.rgb[2] << 16);
    }
    if (records.empty()) continue;
    bool disjoint = true;
    for (const ClipBox& b : f.boxes)
      disjoint =
          disjoint && (glm::any(glm::lessThan(box.max, b.min)) || glm::any(glm::greaterThan(box.min, b.max)));
    nodesOutside += disjoint;
  }
  ASSERT_GT(nodesOutside, 0u);
  RenderSettings s;
  s.method = pointMethod("lod");
  s.precision = 3;
  s.minNodePx = 0;
  s.background = 0;
  s.frames = 1;
  s.warmup = 0;
  s.filter = f;
  lod::LodOptions options;
  options.gpuBytes = 64ull << 20;
  options.readers = 2;
  options.stagingBytes = 8ull << 20;
  Renderer renderer(*context, kWidth, kHeight);
  lod::LodScene scene(*context, tree, options);
  const FrameStats stats = renderer.render(scene, sideCamera(), s);
  const std::vector<uint32_t> image = renderer.image();
  ASSERT_TRUE(stats.batch);
  EXPECT_EQ(stats.batch->batchesClipped, nodesOutside) << "nodes wholly outside both boxes";
  EXPECT_EQ(stats.batch->batchesRendered + stats.batch->batchesClipped, stats.batch->batchesProcessed);
  size_t shown = 0;
  for (uint32_t c : image)
    if (c != 0) {
      ++shown;
      EXPECT_TRUE(keptColors.count(c)) << "pixel shows a point the clip drops: " << std::hex << c;
      if (!keptColors.count(c)) break;
    }
  EXPECT_GT(shown, size_t(kWidth * kHeight / 10));
  // The same points drawn by atomicmin, as a subset: the LOD image decodes positions from its nodes' 30-bit
  // quantization, so an ulp of depth may decide a few pixels otherwise (lod_test.cpp).
  const PointCloud all = tree.cloud();
  PointCloud subset = keptSubset(all, f);
  const Drawn reference = draw(*context, subset, "atomicmin", PointFilter{});
  size_t same = 0, either = 0;
  for (size_t i = 0; i < image.size(); ++i) {
    if (image[i] == 0 && reference.image[i] == 0) continue;
    ++either;
    same += image[i] == reference.image[i];
  }
  EXPECT_GE(double(same), 0.999 * double(either));
}

TEST_F(GpuTest, ClipHighlightTintsTheInsidePoints) {
  const PointCloud cloud = gridCloud(40000, 5);
  const PointFilter f = boxFilter(ClipMode::Highlight);
  // The documented tint: each channel halfway to (255, 200, 0), rounded up; alpha kept.
  PointCloud tinted = cloud;
  size_t inside = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!insideReference(f, worldOf(cloud, i))) continue;
    ++inside;
    const uint32_t c = cloud.colors[i];
    tinted.colors[i] = (c & 0xFF000000u) | ((c & 0xFF) + 256) / 2 | (((c >> 8 & 0xFF) + 201) / 2) << 8 |
                       (((c >> 16 & 0xFF) + 1) / 2) << 16;
  }
  ASSERT_GT(inside, cloud.size() / 10);
  for (const char* method : {"atomicmin", "batch"}) {
    RenderSettings s;
    s.method = parseMethod(method);
    s.background = 0;
    s.precision = 3;
    s.filter = f; // drops nothing: highlight is in the colors
    UploadOptions upload;
    upload.progress = false;
    upload.layout = methodInfo(s.method).layout;
    upload.colors = DisplayColorMode{DisplayColorMode::Source::Rgb};
    upload.filter = f;
    GpuScene highlighted(*context, cloud, upload);
    Renderer renderer(*context, kWidth, kHeight);
    renderer.render(highlighted, sideCamera(), s);
    const std::vector<uint32_t> image = renderer.image();
    upload.filter.reset();
    GpuScene reference(*context, tinted, upload);
    RenderSettings noFilter = s;
    noFilter.filter = PointFilter{};
    renderer.render(reference, sideCamera(), noFilter);
    EXPECT_TRUE(image == renderer.image()) << method << ": highlight differs from the tinted colors";
    // Every lit pixel of the plain render is either unchanged or tinted.
    GpuScene plain(*context, cloud, upload);
    renderer.render(plain, sideCamera(), s);
    const std::vector<uint32_t> untinted = renderer.image();
    size_t changed = 0;
    for (size_t i = 0; i < image.size(); ++i)
      changed += image[i] != untinted[i];
    EXPECT_GT(changed, size_t(kWidth * kHeight / 20)) << method;
  }
}

TEST(ClipVolumes, TooManyVolumesIsAnInputError) {
  PointFilter f;
  f.boxes.resize(shared::kMaxClipBoxes + 1, ClipBox{{0, 0, 0}, {1, 1, 1}});
  EXPECT_THROW(gpuClipVolumes(f, glm::dvec3(0)), InputError);
  f.boxes.clear();
  f.polygons.push_back({{{0, 0}, {1, 0}}});
  EXPECT_THROW(checkGpuClip(f), InputError);
  f.polygons.back().vertices.push_back({0, 1});
  const shared::ClipVolumes c = gpuClipVolumes(f, glm::dvec3(10, 20, 30));
  EXPECT_EQ(c.mode, shared::kClipInside);
  EXPECT_EQ(c.polygons, 1u);
  EXPECT_EQ(c.vertices[0][0], -10.0f);
  EXPECT_EQ(c.vertices[0][3], -20.0f);
  EXPECT_EQ(c.vertices[1][1], -19.0f);
  f.clipMode = ClipMode::Highlight;
  EXPECT_EQ(gpuClipVolumes(f, glm::dvec3(0)).mode, shared::kClipNone) << "highlight drops nothing";
}

} // namespace pointrast::test

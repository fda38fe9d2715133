// A scene uploaded into the buffers of the scene it replaces (UploadOptions::recycle) draws exactly what a
// fresh upload of the same points draws, in both layouts:
// - the same number of points, other points: every buffer reused, nothing allocated;
// - a smaller cloud after a larger one, with parts, a short last batch and a point count that is no
//   multiple of four (the padding batch-prefetch loads): the old cloud lies in front of the new one, so
//   any old point the new scene drew would win pixels;
// - a larger cloud after a smaller one: the buffers that do not fit are allocated.
#include <map>
#include <memory>
#include <random>
#include <tuple>

#include "gpu_fixture.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace pointrast::test {

namespace {

constexpr uint32_t kWidth = 160, kHeight = 120;

// One renderer for the file: on lavapipe making pipelines costs more than drawing these scenes.
Renderer& rendererFor(gpu::Context& context) {
  static std::map<gpu::Context*, std::unique_ptr<Renderer>> kept;
  std::unique_ptr<Renderer>& r = kept[&context];
  if (!r) r = std::make_unique<Renderer>(context, kWidth, kHeight);
  return *r;
}

struct Drawn {
  std::vector<uint64_t> words;
  std::vector<uint32_t> image;
};

Drawn draw(gpu::Context& context, const GpuScene& scene, Method method) {
  Renderer& renderer = rendererFor(context);
  RenderSettings settings;
  settings.method = method;
  settings.captureWords = true;
  settings.warmup = 0;
  settings.background = 0;
  renderer.render(scene, axisCamera(), settings);
  return {renderer.framebufferWords(), renderer.image()};
}

// `count` points in the box of center (0, 0, -depth) and half size (half, half, 0.5), random colors.
PointCloud boxCloud(uint64_t seed, size_t count, double depth, double half) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<glm::dvec3> points(count);
  std::vector<uint32_t> colors(count);
  for (size_t i = 0; i < count; ++i) {
    points[i] = {u(rng) * half, u(rng) * half, -depth + u(rng) * 0.5};
    colors[i] = 0xFF000000u | uint32_t(rng() & 0xFFFFFF);
  }
  return cloudFromPoints(points, colors);
}

struct Case {
  Method method;
  SceneLayout layout;
};
std::vector<Case> cases() {
  return {{pointMethod("atomicmin"), SceneLayout::Float},
          {pointMethod("batch-prefetch"), SceneLayout::Batched}};
}

UploadOptions options(SceneLayout layout, uint64_t maxPartPoints, SceneBuffers* recycle = nullptr) {
  UploadOptions o;
  o.layout = layout;
  o.progress = false;
  o.maxPartPoints = maxPartPoints;
  o.keepStaging = true;
  o.recycle = recycle;
  return o;
}

size_t lit(const std::vector<uint32_t>& image) {
  size_t n = 0;
  for (uint32_t c : image)
    n += c != 0;
  return n;
}

// Draws `second` uploaded into the buffers of a scene of `first`, and a fresh upload of it; both frames
// must be the same word for word. Returns the recycled scene's upload times.
UploadTimes expectSameAsFresh(gpu::Context& context, const Case& c, const PointCloud& first,
                              const PointCloud& second, uint64_t maxPartPoints) {
  GpuScene old(context, first, options(c.layout, maxPartPoints));
  const Drawn before = draw(context, old, c.method);
  EXPECT_GT(lit(before.image), 0u);
  SceneBuffers buffers = old.takeBuffers();
  EXPECT_EQ(old.pointCount(), 0u);
  EXPECT_TRUE(old.parts().empty());
  EXPECT_FALSE(buffers.device.empty());
  EXPECT_FALSE(buffers.staging.empty()); // kept: keepStaging

  GpuScene recycled(context, second, options(c.layout, maxPartPoints, &buffers));
  EXPECT_TRUE(buffers.device.empty() && buffers.staging.empty()) << "the upload takes or frees every buffer";
  const Drawn got = draw(context, recycled, c.method);
  GpuScene fresh(context, second, options(c.layout, maxPartPoints));
  const Drawn want = draw(context, fresh, c.method);
  EXPECT_GT(lit(want.image), 0u);
  EXPECT_NE(want.words, before.words) << "the two clouds must draw differently for the test to mean anything";
  EXPECT_EQ(got.words, want.words);
  EXPECT_EQ(got.image, want.image);
  EXPECT_EQ(recycled.parts().size(), fresh.parts().size());
  return recycled.uploadTimes();
}

} // namespace

class SceneRecycle : public GpuTest {};

TEST_F(SceneRecycle, SameSizeReusesEveryBufferAndDrawsTheNewPoints) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.method.name());
    const PointCloud a = boxCloud(1, 30000, 3, 2), b = boxCloud(2, 30000, 3, 2);
    const UploadTimes times = expectSameAsFresh(*context, c, a, b, 0);
    EXPECT_EQ(times.allocatedBytes, 0u);
    EXPECT_GT(times.reusedBytes, 30000u * 16);
  }
}

TEST_F(SceneRecycle, SmallerCloudDrawsNoOldPoint) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.method.name());
    // Old: 3 parts of 20480, 20480, 9041 points, in front. New: 2 parts of 20480 and 15001 points (a short
    // last batch, a count that is no multiple of four) behind it, in the old first two parts' buffers.
    const PointCloud a = boxCloud(3, 50001, 2, 2), b = boxCloud(4, 35481, 4, 4);
    const UploadTimes times = expectSameAsFresh(*context, c, a, b, 20480);
    EXPECT_EQ(times.allocatedBytes, 0u);
    EXPECT_GT(times.reusedBytes, 0u);
  }
}

TEST_F(SceneRecycle, LargerCloudAllocatesWhatDoesNotFit) {
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.method.name());
    const PointCloud a = boxCloud(5, 12000, 4, 4), b = boxCloud(6, 40003, 2, 2);
    const UploadTimes times = expectSameAsFresh(*context, c, a, b, 0);
    EXPECT_GE(times.allocatedBytes, 40003u * 16);
  }
}

TEST_F(SceneRecycle, MuchSmallerCloudFreesTheLargeBuffers) {
  // A cloud under half the size of the old one takes none of its device buffers (they are freed): a
  // small cloud does not keep a large one's memory.
  const PointCloud a = boxCloud(7, 40000, 2, 2), b = boxCloud(8, 9000, 4, 4);
  const UploadTimes times = expectSameAsFresh(*context, cases()[1], a, b, 0);
  EXPECT_GE(times.allocatedBytes, 9000u * 16);
}

} // namespace pointrast::test

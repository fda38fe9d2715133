// The GPU side of the benchmark on whatever device is present (lavapipe in CI): copy bandwidth, the
// outside view drawing nothing, reordered copies keeping every point.
#include <algorithm>

#include <gtest/gtest.h>

#include "bench/runner.h"
#include "cloud/generate.h"
#include "gpu/bandwidth.h"
#include "gpu/gpu_fixture.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace {

using namespace pointrast;
using test::GpuTest;

class BenchGpu : public GpuTest {};

TEST_F(BenchGpu, CopyBandwidthIsMeasured) {
  gpu::CopyBandwidth copy = gpu::measureCopy(*context, 16 << 20, 3);
  EXPECT_EQ(copy.bytes, uint64_t(16) << 20);
  EXPECT_EQ(copy.repeats, 3);
  EXPECT_GT(copy.medianMs, 0.0);
  EXPECT_NEAR(copy.bytesPerSecond, 2.0 * copy.bytes / (copy.medianMs * 1e-3), copy.bytesPerSecond * 1e-9);
  EXPECT_LE(gpu::copyBytesFor(*context, uint64_t(1) << 50), context->deviceLocalBytes() / 4);
  EXPECT_EQ(gpu::copyBytesFor(*context, 1000), 4096u);
}

TEST_F(BenchGpu, OutsideViewDrawsOnlyBackground) {
  GenerateOptions options;
  options.points = 20'000;
  options.progress = false;
  PointCloud cloud = generateScene(Scene::Terrain, options);
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(*context, cloud, upload);
  Renderer renderer(*context, 160, 100);
  RenderSettings settings;
  for (bench::View view : bench::allViews()) {
    Camera camera = bench::viewCamera(view, cloud.bounds, 1.6);
    renderer.render(scene, camera, settings);
    std::vector<uint32_t> image = renderer.image();
    size_t drawn =
        std::count_if(image.begin(), image.end(), [&](uint32_t p) { return p != settings.background; });
    if (view == bench::View::Outside)
      EXPECT_EQ(drawn, 0u);
    else
      EXPECT_GT(drawn, 0u) << bench::viewName(view);
  }
}

TEST_F(BenchGpu, RunSkipsWhatDoesNotFitAndSaysSo) {
  bench::BenchConfig config;
  bench::Dataset tiny{"tiny", "tiny (terrain, 2k)", "terrain", 2000, 1, false};
  // More points than any device holds: skipped from the estimate alone, never generated.
  bench::Dataset huge{"huge", "huge (tls, 1T)", "tls", uint64_t(1) << 40, 1, false};
  config.datasets = {huge, tiny};
  config.methods = {Method::AtomicMin, Method::Dedup};
  config.orders = {Order::Original, Order::ShuffledMorton};
  config.views = {bench::View::Closeup};
  config.width = 64;
  config.height = 32;
  config.frames = 1;
  config.copyBytes = 1 << 20;
  config.copyRepeats = 2;
  config.progress = false;
  std::vector<std::string> notes;
  size_t calls = 0, lastTotal = 0;
  bench::BenchCallbacks callbacks;
  callbacks.onNote = [&](const std::string& line) { notes.push_back(line); };
  callbacks.onResult = [&](const bench::BenchRun& run, const bench::Result&, size_t done, size_t total) {
    EXPECT_GT(run.copy.bytesPerSecond, 0.0) << "the copy bandwidth is known before the first result";
    EXPECT_EQ(done, ++calls);
    lastTotal = total;
  };
  bench::BenchRun run = bench::runBench(*context, config, callbacks);
  ASSERT_EQ(run.datasets.size(), 2u);
  EXPECT_TRUE(run.datasets[0].skipped);
  EXPECT_NE(run.datasets[0].reason.find("does not fit: needs "), std::string::npos) << run.datasets[0].reason;
  EXPECT_FALSE(run.datasets[1].skipped);
  EXPECT_EQ(run.datasets[1].points, 2000u);
  EXPECT_EQ(run.results.size(), 4u);
  EXPECT_EQ(calls, 4u);
  EXPECT_EQ(lastTotal, 4u);
  EXPECT_TRUE(std::any_of(notes.begin(), notes.end(), [](const std::string& n) {
    return n.rfind("huge (tls, 1T): skipped, it does not fit", 0) == 0;
  }));
  for (const bench::Result& r : run.results) {
    EXPECT_EQ(r.dataset, "tiny");
    std::string why;
    if (Renderer::supports(*context, r.method, &why)) {
      EXPECT_TRUE(r.ok()) << r.reason;
      EXPECT_GT(r.stats.medianMs, 0.0);
      EXPECT_EQ(r.stats.frames, 1u);
      EXPECT_GT(r.copyFraction, 0.0);
    } else {
      EXPECT_EQ(r.status, "unsupported");
      EXPECT_EQ(r.reason, why);
    }
  }
}

TEST(BenchCloud, ReorderedCopyIsAPermutationWithTheSameBounds) {
  GenerateOptions options;
  options.points = 30'000;
  options.progress = false;
  PointCloud cloud = generateScene(Scene::Tls, options);
  for (Order order : {Order::Morton, Order::Shuffled, Order::ShuffledMorton}) {
    PointCloud copy = bench::reorderedCopy(cloud, order, 7);
    ASSERT_EQ(copy.size(), cloud.size());
    EXPECT_EQ(copy.bounds.min, cloud.bounds.min);
    EXPECT_EQ(copy.bounds.max, cloud.bounds.max);
    // Same multiset of (position, color): compare sorted keys.
    auto keys = [](const PointCloud& c) {
      std::vector<std::tuple<int32_t, int32_t, int32_t, uint32_t>> k(c.size());
      for (uint64_t i = 0; i < c.size(); ++i)
        k[i] = {c.positions[3 * i], c.positions[3 * i + 1], c.positions[3 * i + 2], c.colors[i]};
      std::sort(k.begin(), k.end());
      return k;
    };
    EXPECT_EQ(keys(copy), keys(cloud)) << orderName(order);
    EXPECT_NE(copy.positions, cloud.positions) << orderName(order) << " changed nothing";
  }
}

} // namespace

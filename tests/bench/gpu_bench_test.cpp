// The GPU side of the benchmark on whatever device is present (lavapipe in CI): copy bandwidth, the
// outside view drawing nothing, reordered copies keeping every point.
#include <algorithm>
#include <chrono>
#include <vector>

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

// A run small enough for lavapipe: 64x32 pixels, a 1 MiB copy measured twice, no progress lines.
bench::BenchConfig smallConfig(std::vector<bench::Dataset> datasets, std::vector<Method> methods,
                               std::vector<Order> orders, std::vector<bench::View> views, uint32_t frames) {
  bench::BenchConfig config;
  config.datasets = std::move(datasets);
  config.methods = std::move(methods);
  config.orders = std::move(orders);
  config.views = std::move(views);
  config.width = 64;
  config.height = 32;
  config.frames = frames;
  config.copyBytes = 1 << 20;
  config.copyRepeats = 2;
  config.progress = false;
  return config;
}

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
  bench::Dataset tiny{"tiny", "tiny (terrain, 2k)", "terrain", 2000, 1, false};
  // More points than any device holds: skipped from the estimate alone, never generated.
  bench::Dataset huge{"huge", "huge (tls, 1T)", "tls", uint64_t(1) << 40, 1, false};
  bench::BenchConfig config =
      smallConfig({huge, tiny}, {pointMethod("atomicmin"), pointMethod("dedup")},
                  {Order::Original, Order::ShuffledMorton}, {bench::View::Closeup}, 1);
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

TEST(BenchBudget, SlowMethodsGetFewerFramesFastOnesAll) {
  // 10 frames after 2 warm-up: 12 probe-lengths must fit the budget.
  EXPECT_EQ(bench::budgetedFrames(10, 2, 0.1, 1.2), 10u);
  EXPECT_EQ(bench::budgetedFrames(10, 2, 0.1, 1.1), 10u) << "11 fit: every frame still timed";
  EXPECT_EQ(bench::budgetedFrames(10, 2, 0.2, 1.2), 6u);
  EXPECT_EQ(bench::budgetedFrames(10, 2, 2.0, 1.0), 3u) << "never fewer than 3";
  EXPECT_EQ(bench::budgetedFrames(10, 2, 2.0, 1.0, 1), 1u);
  EXPECT_EQ(bench::budgetedFrames(2, 2, 2.0, 1.0), 2u) << "never more than asked for";
  EXPECT_EQ(bench::budgetedFrames(10, 2, 5.0, 0.0), 10u) << "0 = no limit";
}

TEST_F(BenchGpu, BudgetShortensEveryCombinationOfASlowRun) {
  bench::BenchConfig config = smallConfig(
      {bench::Dataset{"tiny", "tiny (terrain, 20k)", "terrain", 20'000, 1, false}},
      {pointMethod("atomicmin"), pointMethod("hqs1r")}, {Order::Original}, {bench::View::Overview}, 10);
  // Far less than any frame takes: every combination is timed over the minimum of 3 frames.
  config.secondsPerCombination = 1e-9;
  bench::BenchRun run = bench::runBench(*context, config, {});
  ASSERT_EQ(run.results.size(), 2u);
  for (const bench::Result& r : run.results) {
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_EQ(r.stats.frames, bench::kMinBudgetedFrames) << methodName(r.method);
    EXPECT_GT(r.stats.medianMs, 0.0);
  }
  config.secondsPerCombination = 0;
  run = bench::runBench(*context, config, {});
  for (const bench::Result& r : run.results)
    EXPECT_EQ(r.stats.frames, 10u) << methodName(r.method);
}

TEST(BenchTimeLimit, StopsOnlyOnceTheLimitHasPassed) {
  const auto now = std::chrono::steady_clock::now();
  EXPECT_NO_THROW(bench::checkTimeLimit(now - std::chrono::hours(1), 0, 1, 2)) << "0 = no limit";
  EXPECT_NO_THROW(bench::checkTimeLimit(now, 3600, 1, 2));
  try {
    bench::checkTimeLimit(now - std::chrono::seconds(10), 5, 3, 7);
    ADD_FAILURE() << "no TimeLimitReached";
  } catch (const bench::TimeLimitReached& e) {
    EXPECT_EQ(std::string(e.what()),
              "time limit of 5 s reached after 3 of 7 combinations; the rest were not run");
  }
}

TEST_F(BenchGpu, TimeLimitEndsTheRunWithWhatItMeasured) {
  bench::BenchConfig config =
      smallConfig({bench::Dataset{"tiny", "tiny (terrain, 20k)", "terrain", 20'000, 1, false}},
                  {pointMethod("atomicmin"), pointMethod("earlyz")}, {Order::Original, Order::Morton},
                  {bench::View::Overview}, 3);
  config.timeLimitSeconds = 1e-9; // passed before the first data set is prepared
  bench::BenchRun run = bench::runBench(*context, config, {});
  EXPECT_TRUE(run.results.empty());
  EXPECT_NE(run.stopped.find("time limit of 1e-09 s reached after 0 of 4 combinations"), std::string::npos)
      << run.stopped;
  config.timeLimitSeconds = 3600;
  run = bench::runBench(*context, config, {});
  EXPECT_EQ(run.results.size(), 4u);
  EXPECT_TRUE(run.stopped.empty()) << run.stopped;
}

TEST(BenchClocks, SettlesOnceTwoRoundsAgreeAfterAFifthOfASecond) {
  // A GPU that runs 5.7x slow for its first two rounds, then at full speed.
  std::vector<double> times = {5.7, 5.7, 1.0, 1.01, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
  std::vector<uint32_t> frames;
  double now = 100; // a clock that each round moves by 60 ms, however loaded the machine is
  const double seconds = bench::settleClocks(
      [&](uint32_t n) {
        frames.push_back(n);
        now += 0.06;
        return times[std::min(frames.size() - 1, times.size() - 1)];
      },
      [&] { return now; });
  ASSERT_EQ(frames.size(), 4u) << "not before the slow rounds have passed and 0.2 s, no longer than needed";
  EXPECT_NEAR(seconds, 0.24, 1e-9);
  EXPECT_EQ(frames[0], 1u);
  EXPECT_EQ(frames[1], 6u) << "about 30 ms of frames of 5.7 ms";
  EXPECT_EQ(frames[3], 30u);
  int calls = 0;
  bench::settleClocks([&](uint32_t) { return ++calls, 0.0; });
  EXPECT_EQ(calls, 1) << "nothing to time: no settling";
}

// A device that takes times[i] ms a frame in round i (the last one from then on), on a clock that each round
// moves by secondsPerRound (binary fractions, so that the elapsed times are exact).
struct SettleRun {
  size_t rounds = 0; // calls of renderMs
  double seconds = 0;
};
SettleRun settleOn(const std::vector<double>& times, double secondsPerRound) {
  SettleRun run;
  double now = 100;
  run.seconds = bench::settleClocks(
      [&](uint32_t) {
        now += secondsPerRound;
        return times[std::min(run.rounds++, times.size() - 1)];
      },
      [&] { return now; });
  return run;
}

TEST(BenchClocks, TwoEquallySlowRoundsAfterAFasterOneDoNotSettle) {
  // Clocks that fall again after a fast round: the slow rounds agree with one another, not with the best.
  EXPECT_EQ(settleOn({1.0, 1.0, 5.7, 5.7, 5.7, 1.02, 1.0, 1.0}, 0.125).rounds, 7u)
      << "on the fast pair (rounds 5 and 6), not on 5.7 ms";
  // Slow, slow, fast, fast: not on the first two, though 0.2 s have passed after them.
  EXPECT_EQ(settleOn({5.7, 5.7, 1.0, 1.0}, 0.125).rounds, 4u);
}

TEST(BenchClocks, SteadyRoundsSettleAfterTheMinimumTime) {
  EXPECT_EQ(settleOn({2.0}, 1.0 / 64).rounds, 13u) << "0.2 s of rounds of 1/64 s";
  EXPECT_EQ(settleOn({2.0}, 0.25).rounds, 3u) << "the probe round and two rounds that agree";
}

TEST(BenchClocks, NoisyRoundsSettleWhenTwoInARowAreWithinThreePercentOfTheBest) {
  // 1.00 is the best from round 1: 1.05 and 1.04 are not within 3 % of it (1.05 and 1.02 are within 3 % of
  // each other), 1.02 and 1.01 are.
  EXPECT_EQ(settleOn({1.3, 1.0, 1.05, 1.02, 1.04, 1.02, 1.01, 1.2}, 0.125).rounds, 7u);
  // A new best moves the bar: 1.0 and 1.01 agree with each other, not with 0.9.
  EXPECT_EQ(settleOn({1.3, 1.0, 0.9, 1.0, 1.01, 0.91, 0.9}, 0.125).rounds, 7u);
}

TEST(BenchClocks, RoundsThatNeverSettleStopAtTheCap) {
  // Alternating speeds never have two rounds in a row near the best.
  std::vector<double> alternating;
  for (int i = 0; i < 400; ++i)
    alternating.push_back(i % 2 == 0 ? 1.0 : 2.0);
  const SettleRun timed = settleOn(alternating, 0.125);
  EXPECT_EQ(timed.rounds, 24u) << "3 s of rounds of 1/8 s";
  EXPECT_EQ(timed.seconds, 3.0);
  EXPECT_EQ(settleOn(alternating, 0).rounds, size_t(bench::kSettleMaxRounds)) << "a clock that stands still";
}

} // namespace

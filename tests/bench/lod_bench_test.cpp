// The bench side of the LOD methods on lavapipe, with octrees written from the tests' in-memory builder
// (gpu/lod_octree.h) through PotreeWriter, cached in a folder:
// - paper2022 measures lod and lod-hqs on each data set's octree (once whatever the orders), the octree is
//   reused from the cache by a second run, and without octrees their results say why;
// - the reports hold the LOD half of Table 2 with the speed-up over batch-prefetch, and the octrees' builds;
// - the lod suite's sweeps and streaming run at a tiny scale and write their three reports.
#include <chrono>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "bench/lod_report.h"
#include "bench/lod_runner.h"
#include "bench/lod_suite.h"
#include "bench/report.h"
#include "bench/suites.h"
#include "gpu/gpu_fixture.h"
#include "gpu/lod_octree.h"
#include "io/potree/potree.h"

namespace {

using namespace pointrast;
using namespace pointrast::bench;

std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("pointrast-lod-bench-" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Octrees in `dir`: built by the tests' rule and written with PotreeWriter when missing.
OctreeProvider testOctrees(const std::filesystem::path& dir, int* builds = nullptr) {
  return [dir, builds](const std::string& name, const std::function<const PointCloud&()>& points) {
    DatasetOctree o;
    o.path = dir / name;
    if (std::filesystem::exists(o.path / "metadata.json")) {
      o.reused = true;
    } else {
      const auto start = std::chrono::steady_clock::now();
      test::MemoryOctree tree;
      test::buildOctree(tree, points(), 1500);
      io::PotreeWriter writer(o.path, tree.meta, {});
      for (const auto& [key, records] : tree.nodes)
        writer.writeNode(key, records.data(), records.size());
      writer.commit();
      o.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      o.phases = "test build";
      if (builds) ++*builds;
    }
    for (const auto& entry : std::filesystem::directory_iterator(o.path))
      o.bytes += entry.file_size();
    o.points = io::openPotree(o.path)->metadata().pointCount;
    return o;
  };
}

Dataset terrain(uint64_t points) {
  Dataset d;
  d.source = "terrain";
  d.points = points;
  d.name = "terrain-" + shortCount(points);
  d.label = d.name;
  return d;
}

TEST(LodSuites, LodSuiteAndPaper2022CarryTheLodMethods) {
  std::vector<Dataset> lod = suiteDatasets("lod", 1.0, 1);
  ASSERT_EQ(lod.size(), 1u);
  EXPECT_EQ(lod[0].points, 1'000'000'000u);
  // The same name, size and seed as paper2022's aerial1g: both suites share its octree.
  EXPECT_EQ(octreeKey(lod[0]), octreeKey(suiteDatasets("paper2022", 1.0, 1)[3]));
  EXPECT_EQ(octreeKey(lod[0]), "aerial1g-like-1000000000-seed1");
  EXPECT_TRUE(isLodSuite("lod"));
  EXPECT_FALSE(isLodSuite("paper2022"));
  EXPECT_EQ(suiteDefaults("lod").methods, std::vector<Method>({pointMethod("lod")}));
  EXPECT_EQ(suiteDefaults("lod").width, 2560u);
  const std::vector<std::string> names = suiteNames(); // one vector: begin and end of the same range
  EXPECT_NE(std::find(names.begin(), names.end(), "lod"), names.end());
  EXPECT_EQ(layoutsOf({pointMethod("lod"), pointMethod("batch")}),
            std::vector<SceneLayout>({SceneLayout::Batched}))
      << "no GPU scene for the octree methods";
}

class LodBench : public test::GpuTest {};

TEST_F(LodBench, Paper2022MeasuresTheLodMethodsOnEachDataSetsOctree) {
  const std::filesystem::path cache = scratch("octrees");
  int builds = 0;
  BenchConfig config;
  config.datasets = {terrain(60'000)};
  config.methods = {pointMethod("batch-prefetch"), pointMethod("lod"), pointMethod("lod-hqs")};
  config.orders = {Order::Morton, Order::Original};
  config.views = {View::Overview, View::Closeup};
  config.width = 160;
  config.height = 100;
  config.frames = 2;
  config.copyBytes = 1 << 20;
  config.copyRepeats = 2;
  config.progress = false;
  config.octrees = testOctrees(cache, &builds);
  size_t callbacks = 0, total = 0;
  BenchCallbacks cb;
  cb.onResult = [&](const BenchRun&, const Result&, size_t done, size_t all) {
    callbacks = done;
    total = all;
  };
  BenchRun run = runBench(*context, config, cb);
  // batch-prefetch: 2 orders x 2 views; the LOD methods: 2 views each, once whatever the orders.
  ASSERT_EQ(run.results.size(), 4u + 4u);
  EXPECT_EQ(callbacks, total);
  EXPECT_EQ(total, 8u);
  EXPECT_EQ(builds, 1);
  ASSERT_EQ(run.octrees.size(), 1u);
  EXPECT_FALSE(run.octrees[0].second.reused);
  EXPECT_EQ(run.octrees[0].second.points, 60'000u);
  for (const Result& r : run.results) {
    ASSERT_TRUE(r.ok()) << methodName(r.method) << ": " << r.reason;
    const bool lod = methodInfo(r.method).layout == SceneLayout::Octree;
    EXPECT_EQ(bool(r.stats.lod), lod) << methodName(r.method);
    if (!lod) continue;
    EXPECT_EQ(r.order, Order::Morton) << "filed under the data set's first order";
    EXPECT_GT(r.stats.batch->batchesProcessed, 0u);
    EXPECT_GT(r.pointsPerSecond, 0);
    if (r.view == View::Overview) {
      EXPECT_LT(r.stats.lod->pointsSelected, 60'000u) << "LOD-culled at 100 px";
    }
  }
  ReportInfo info{"p", "p", "pointrast bench", "2024-01-01T00:00:00Z"};
  const std::string md = markdownReport(run, info);
  EXPECT_NE(md.find("## LOD statistics per frame (the 2022 paper's Table 2, octrees)"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| terrain-60k | overview | lod |"), std::string::npos) << md;
  EXPECT_NE(md.find("### Octrees"), std::string::npos) << md;
  EXPECT_NE(md.find("| terrain-60k | 60k |"), std::string::npos) << md;
  EXPECT_NE(md.find("x |\n"), std::string::npos) << "a speed-up over batch-prefetch\n" << md;
  // The LOD rows are columns of Table 1 and stay out of the batch table.
  EXPECT_NE(md.find("| batch-prefetch | lod | lod-hqs |"), std::string::npos) << md;
  EXPECT_EQ(md.find("| terrain-60k | morton | overview | lod |"), std::string::npos) << md;
  const nlohmann::json j = runJson(run, info);
  EXPECT_EQ(j["octrees"].size(), 1u);
  bool lodStats = false;
  for (const nlohmann::json& r : j["results"])
    lodStats = lodStats || r.contains("lod_stats");
  EXPECT_TRUE(lodStats);

  // A second run finds the octree in the cache; a run without octrees says why.
  BenchRun again = runBench(*context, config);
  EXPECT_EQ(builds, 1);
  ASSERT_EQ(again.octrees.size(), 1u);
  EXPECT_TRUE(again.octrees[0].second.reused);
  config.octrees = nullptr;
  BenchRun none = runBench(*context, config);
  for (const Result& r : none.results)
    if (methodInfo(r.method).layout == SceneLayout::Octree) {
      EXPECT_EQ(r.status, "unsupported");
      EXPECT_NE(r.reason.find("no octree"), std::string::npos) << r.reason;
    }
  std::filesystem::remove_all(cache.parent_path());
}

TEST_F(LodBench, LodSuiteSweepsAndStreamsAtATinyScale) {
  const std::filesystem::path cache = scratch("suite");
  LodSuiteConfig config;
  config.datasets = {terrain(80'000)};
  config.width = 160;
  config.height = 100;
  config.frames = 1;
  config.views = {View::Overview};
  config.pointBudgets = {5'000, 0};
  config.minNodePx = {100, 0};
  config.flightFrames = 6;
  config.jumps = 2;
  config.displayHz = 0;
  config.copyBytes = 1 << 20;
  config.copyRepeats = 2;
  config.progress = false;
  config.octrees = testOctrees(cache);
  LodSuiteRun run = runLodSuite(*context, config);
  EXPECT_TRUE(run.stopped.empty()) << run.stopped;
  ASSERT_EQ(run.sweeps.size(), 4u);
  for (const LodSweepResult& r : run.sweeps) {
    ASSERT_TRUE(r.ok()) << r.reason;
    if (r.pointBudget) {
      EXPECT_LE(r.stats.lod->pointsSelected, r.pointBudget);
    }
    if (r.minNodePx == 0 && r.pointBudget == 0) {
      EXPECT_EQ(r.stats.lod->pointsSelected, 80'000u);
    }
  }
  ASSERT_EQ(run.streams.size(), 1u);
  const LodStreamResult& s = run.streams[0];
  ASSERT_TRUE(s.ok()) << s.reason;
  EXPECT_EQ(s.flight.size(), 6u);
  // An eighth of the octree, in whole pages, and at least 16 pages (1 MiB).
  const uint64_t page = shared::kLodPageBytes;
  EXPECT_EQ(s.cacheBytes, std::max<uint64_t>(s.octreeGpuBytes / 8 / page, 16) * page);
  ASSERT_EQ(s.jumps.size(), 2u);
  for (const LodJumpResult& jump : s.jumps) {
    EXPECT_TRUE(jump.converged) << jump.camera;
    EXPECT_GE(jump.frames, 1u);
  }
  EXPECT_GT(s.last.bytesStreamed, 0u);
  ReportInfo info{"lod-tiny", "lod (tiny)", "pointrast bench --suite lod", "2024-01-01T00:00:00Z"};
  const std::string md = lodSuiteMarkdown(run, info);
  EXPECT_NE(md.find("## Render time against the point budget"), std::string::npos) << md;
  EXPECT_NE(md.find("| terrain-80k | overview |"), std::string::npos) << md;
  EXPECT_NE(md.find("Targets: every frame of the flight at >= 60 fps"), std::string::npos) << md;
  const nlohmann::json j = lodSuiteJson(run, info);
  EXPECT_EQ(j["streams"][0]["flight"]["frames"], 6);
  EXPECT_EQ(j["streams"][0]["flight"]["per_frame_gpu_ms"].size(), 6u);
  EXPECT_EQ(j["sweeps"].size(), 4u);
  const WrittenFiles files = writeLodSuiteReports(run, info, cache / "reports");
  EXPECT_TRUE(std::filesystem::exists(files.json));
  EXPECT_TRUE(std::filesystem::exists(files.markdown));
  EXPECT_TRUE(std::filesystem::exists(files.svg));
  std::filesystem::remove_all(cache.parent_path());
}

TEST(LodReport, Percentiles) {
  EXPECT_EQ(percentile({}, 0.5), 0);
  EXPECT_EQ(percentile({3, 1, 2}, 0.5), 2);
  EXPECT_EQ(percentile({3, 1, 2}, 1.0), 3);
  EXPECT_EQ(percentile({3, 1, 2}, 0.0), 1);
  std::vector<double> hundred;
  for (int i = 1; i <= 100; ++i)
    hundred.push_back(i);
  EXPECT_EQ(percentile(hundred, 0.99), 99);
}

} // namespace

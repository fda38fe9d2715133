// The bench side of the 2022 batch methods: the paper2022 suite (sizes, per-data-set orders and views,
// its defaults), the batch statistics in the JSON and Markdown reports (the paper's Table 2), and a run
// that mixes 2021 and batch methods on lavapipe (both scene layouts uploaded, counted in the estimate).
#include <algorithm>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "bench/report.h"
#include "bench/runner.h"
#include "bench/suites.h"
#include "gpu/gpu_fixture.h"

namespace {

using namespace pointrast;
using namespace pointrast::bench;

TEST(Suites, Paper2022SizesOrdersViewsAndDefaults) {
  std::vector<Dataset> full = suiteDatasets("paper2022", 1.0, 1);
  ASSERT_EQ(full.size(), 5u);
  EXPECT_EQ(full[0].points, 69'000'000u);
  EXPECT_EQ(full[1].points, 279'000'000u);
  EXPECT_EQ(full[2].points, 529'000'000u);
  EXPECT_EQ(full[3].points, 1'000'000'000u);
  EXPECT_EQ(full[3].label, "aerial1g-like (terrain, 1G)");
  EXPECT_EQ(full[4].source, "tls");
  for (const Dataset& d : full) {
    bool study = d.name == "tls-order";
    EXPECT_EQ(d.orders, study ? std::vector<Order>({Order::Original, Order::Morton})
                              : std::vector<Order>({Order::Morton}))
        << d.name;
    bool inside = study || d.name == "scan529m-like";
    EXPECT_EQ(d.views, inside ? std::vector<View>({View::Overview, View::Closeup})
                              : std::vector<View>({View::Overview}))
        << d.name;
  }
  EXPECT_EQ(suiteDatasets("paper2022", 0.001, 1)[3].points, 1'000'000u);
  SuiteDefaults defaults = suiteDefaults("paper2022");
  EXPECT_EQ(defaults.width, 2560u);
  EXPECT_EQ(defaults.height, 1140u);
  EXPECT_EQ(defaults.methods, std::vector<Method>({pointMethod("hw-points"), pointMethod("batch"),
                                                   pointMethod("batch-prefetch"), pointMethod("batch-hqs"),
                                                   pointMethod("dedup"), pointMethod("hqs"), pointMethod("lod"),
                                                   pointMethod("lod-hqs")}));
  EXPECT_EQ(layoutsOf(defaults.methods),
            std::vector<SceneLayout>({SceneLayout::Float, SceneLayout::Batched}));
  const std::vector<Method> family = suiteDefaults("paper2021").methods;
  EXPECT_EQ(family.size(), 11u)
      << "hw-points, the closest-point family (6 with dedup-ballot), busyloop, justset, hqs, hqs1r";
  EXPECT_EQ(layoutsOf(family), std::vector<SceneLayout>({SceneLayout::Float})) << "no batch method";
  EXPECT_NE(std::find(family.begin(), family.end(), pointMethod("hw-points")), family.end());
  EXPECT_NE(std::find(family.begin(), family.end(), pointMethod("hqs1r")), family.end());
  EXPECT_EQ(suiteDefaults("paper2021").width, 1920u);
  EXPECT_THROW(suiteDefaults("paper1999"), InputError);
  EXPECT_THROW(suiteDatasets("paper2022", 1.0, 1, {"retz=/x.las"}), InputError) << "a paper2021 name";
  EXPECT_NE(std::find(suiteNames().begin(), suiteNames().end(), "paper2022"), suiteNames().end());
}

BenchRun runWithBatchResults() {
  BenchRun run;
  run.device.name = "Made-up GPU 9000";
  run.copy.bytesPerSecond = 1e12;
  run.config.methods = {pointMethod("dedup"), pointMethod("batch-prefetch"), pointMethod("batch-hqs")};
  run.config.orders = {Order::Morton, Order::Original};
  run.config.views = {View::Overview, View::Closeup};
  DatasetOutcome d;
  d.dataset.name = "big";
  d.dataset.label = "big (terrain, 1G)";
  d.points = 1'000'000'000;
  run.datasets.push_back(d);
  for (Method m : run.config.methods) {
    Result r;
    r.dataset = "big";
    r.order = Order::Morton;
    r.view = View::Overview;
    r.method = m;
    r.points = d.points;
    r.stats.medianMs = 5;
    r.stats.points = d.points;
    if (m != pointMethod("dedup")) {
      BatchStats b;
      b.batchesProcessed = 97'657;
      b.batchesRendered = 90'000;
      b.pointsProcessed = 921'600'000;
      b.pointsByWords[0] = 900'000'000;
      b.pointsByWords[1] = 21'600'000;
      b.pointsRendered = 12'345'678;
      b.pointsBlended = m == pointMethod("batch-hqs") ? 600'000'000 : 0;
      r.stats.batch = b;
    }
    run.results.push_back(r);
  }
  return run;
}

TEST(Report, BatchStatisticsInJsonAndMarkdown) {
  BenchRun run = runWithBatchResults();
  ReportInfo info{"r", "r", "pointrast bench", "2024-01-01T00:00:00Z"};
  nlohmann::json j = runJson(run, info);
  ASSERT_EQ(j["results"].size(), 3u);
  EXPECT_FALSE(j["results"][0].contains("batch_stats"));
  EXPECT_EQ(j["results"][1]["batch_stats"]["batches_rendered"], 90'000);
  EXPECT_EQ(j["results"][1]["batch_stats"]["points_by_words"][1], 21'600'000);
  EXPECT_EQ(j["results"][2]["batch_stats"]["points_blended"], 600'000'000);
  std::string md = markdownReport(run, info);
  EXPECT_NE(md.find("## Batch statistics per frame (the 2022 paper's Table 2)"), std::string::npos) << md;
  EXPECT_NE(
      md.find("| big (terrain, 1G) | morton | overview | batch-prefetch | 97657 | 90000 | 922M | 98% / 2% / "
              "0% | 12.3M | - | 5.00 |"),
      std::string::npos)
      << md;
  EXPECT_NE(md.find("| batch-hqs | 97657 | 90000 | 922M | 98% / 2% / 0% | 12.3M | 600M |"), std::string::npos)
      << md;
  // Only measured rows: no original-order row, no closeup table rows.
  EXPECT_EQ(md.find("| big (terrain, 1G) | original |"), std::string::npos) << md;
  EXPECT_NE(md.find("Bytes per point: dedup 16, batch-prefetch *, batch-hqs *. *: the bytes the frame read"),
            std::string::npos)
      << md;
}

class BatchBench : public test::GpuTest {};

TEST_F(BatchBench, MixedRunUploadsBothLayoutsAndReportsStatistics) {
  BenchConfig config;
  Dataset tiny{"tiny", "tiny (terrain, 30k)", "terrain", 30'000, 1, false};
  tiny.orders = {Order::Morton};
  tiny.views = {View::Overview};
  Dataset study{"study", "study (tls, 25k)", "tls", 25'000, 1, false};
  study.orders = {Order::Original, Order::Morton};
  study.views = {View::Overview, View::Closeup};
  config.datasets = {tiny, study};
  config.methods = {pointMethod("atomicmin"), pointMethod("batch"), pointMethod("batch-prefetch"),
                    pointMethod("batch-hqs")};
  config.orders = {Order::Morton, Order::Original};
  config.views = {View::Overview, View::Closeup};
  config.width = 96;
  config.height = 64;
  config.frames = 1;
  config.copyBytes = 1 << 20;
  config.copyRepeats = 2;
  config.progress = false;
  BenchRun run = runBench(*context, config);
  // 1 x 1 x 4 + 2 x 2 x 4.
  ASSERT_EQ(run.results.size(), 20u);
  EXPECT_EQ(run.datasets[0].memory.gpuBytes,
            30'000u * 16 + (30'000u * 16 + 3 * 32) + 96u * 64 * kTargetBytesPerPixel);
  for (const Result& r : run.results) {
    std::string where =
        r.dataset + " / " + orderName(r.order) + " / " + viewName(r.view) + " / " + methodName(r.method);
    ASSERT_TRUE(r.ok()) << where << ": " << r.reason;
    bool batched = methodInfo(r.method).layout == SceneLayout::Batched;
    ASSERT_EQ(bool(r.stats.batch), batched) << where;
    if (!batched) continue;
    EXPECT_EQ(r.stats.batch->pointsProcessed + 0, r.stats.batch->pointsByWords[0] +
                                                      r.stats.batch->pointsByWords[1] +
                                                      r.stats.batch->pointsByWords[2]);
    EXPECT_NEAR(r.effectiveBytesPerSecond, double(r.stats.batch->bytesRead) / (r.stats.medianMs * 1e-3),
                r.effectiveBytesPerSecond * 1e-9)
        << where;
  }
  std::string md = markdownReport(run, {"x", "x", "x", "x"});
  EXPECT_NE(md.find("| study (tls, 25k) | original | closeup | batch |"), std::string::npos) << md;
  EXPECT_EQ(md.find("| tiny (terrain, 30k) | original |"), std::string::npos) << md;
}

} // namespace

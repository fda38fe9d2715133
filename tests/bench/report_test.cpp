// Report writers and suites on a made-up run: no GPU needed.
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "bench/report.h"
#include "bench/suites.h"

namespace {

using namespace pointrast;
using namespace pointrast::bench;

BenchRun madeUpRun() {
  BenchRun run;
  run.device.name = "Made-up GPU 9000";
  run.device.typeName = "discrete GPU";
  run.copy.bytes = 1 << 30;
  run.copy.repeats = 10;
  run.copy.bytesPerSecond = 1e12;
  run.config.methods = {pointMethod("atomicmin"), pointMethod("earlyz"), pointMethod("dedup")};
  run.config.orders = {Order::Original, Order::Morton};
  run.config.views = {View::Overview, View::Outside};
  run.config.width = 640;
  run.config.height = 360;
  run.config.frames = 10;
  run.warmup = 2;
  const char* names[] = {"alpha", "beta"};
  double ms = 1.0;
  for (const char* name : names) {
    DatasetOutcome d;
    d.dataset.name = name;
    d.dataset.label = std::string(name) + " (terrain, 1M)";
    d.points = 1'000'000;
    run.datasets.push_back(d);
    for (Order o : run.config.orders)
      for (View v : run.config.views)
        for (Method m : run.config.methods) {
          Result r;
          r.dataset = name;
          r.order = o;
          r.view = v;
          r.method = m;
          r.points = d.points;
          if (m == pointMethod("dedup")) {
            r.status = "unsupported";
            r.reason = "dedup is not available on 'Made-up GPU 9000': needs NV";
          } else {
            r.stats.medianMs = r.stats.minMs = r.stats.maxMs = ms;
            ms *= 1.7; // wide enough for a log axis
            r.stats.frames = 10;
            r.stats.points = d.points;
            r.copyFraction = 0.25;
          }
          run.results.push_back(r);
        }
  }
  DatasetOutcome skipped;
  skipped.dataset.name = "huge";
  skipped.dataset.label = "huge (tls, 796M)";
  skipped.skipped = true;
  skipped.reason = "it does not fit";
  run.datasets.push_back(skipped);
  return run;
}

ReportInfo info() {
  return {"made-up", "made-up run", "pointrast bench x", "2024-01-01T00:00:00Z"};
}

TEST(Report, MarkdownListsCombinationsTheBudgetShortened) {
  BenchRun run = madeUpRun();
  run.config.secondsPerCombination = 2;
  EXPECT_EQ(markdownReport(run, info()).find("Time budget"), std::string::npos) << "nothing shortened";
  int n = 0;
  for (Result& r : run.results)
    if (r.ok() && r.method == pointMethod("atomicmin")) r.stats.frames = ++n % 2 ? 3 : 5;
  const std::string md = markdownReport(run, info());
  EXPECT_NE(md.find("- Time budget 2 s per combination"), std::string::npos) << md;
  EXPECT_NE(md.find("atomicmin " + std::to_string(n) + "x (3-5 frames)"), std::string::npos) << md;
  EXPECT_EQ(md.find("earlyz 4x"), std::string::npos);
  EXPECT_EQ(runJson(run, info())["settings"]["seconds_per_combination"], 2.0);
}

TEST(Report, MarkdownHasOneTablePerViewWithDatasetOrderRows) {
  std::string md = markdownReport(madeUpRun(), info());
  EXPECT_NE(md.find("## overview: median GPU time per frame, ms"), std::string::npos);
  EXPECT_NE(md.find("## outside: median GPU time per frame, ms"), std::string::npos);
  EXPECT_NE(md.find("## overview: effective bandwidth, % of copy bandwidth"), std::string::npos);
  EXPECT_NE(md.find("| data set | order | atomicmin | earlyz | dedup |"), std::string::npos);
  EXPECT_NE(md.find("| alpha (terrain, 1M) | original | 1.00 | 1.70 | n/a |"), std::string::npos) << md;
  EXPECT_NE(md.find("| beta (terrain, 1M) | morton |"), std::string::npos);
  EXPECT_NE(md.find("| alpha (terrain, 1M) | original | 25% | 25% | n/a |"), std::string::npos) << md;
  EXPECT_EQ(md.find("| huge"), std::string::npos) << "a skipped data set has no rows";
  EXPECT_NE(md.find("**skipped**, it does not fit"), std::string::npos);
  EXPECT_NE(md.find("needs NV"), std::string::npos) << "the reason for n/a is given";
  EXPECT_NE(md.find("1000.0 GB/s"), std::string::npos);
}

TEST(Report, SvgIsAChartOfTheMortonOverviewBars) {
  std::string svg = svgChart(madeUpRun(), info());
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("morton order, overview view, log scale"), std::string::npos);
  size_t bars = 0;
  for (size_t at = svg.find("<title>"); at != std::string::npos; at = svg.find("<title>", at + 1))
    ++bars;
  EXPECT_EQ(bars, 4u) << "two data sets x two supported methods";
  EXPECT_NE(svg.find(">n/a<"), std::string::npos);
}

TEST(Report, JsonHoldsEverything) {
  nlohmann::json j = runJson(madeUpRun(), info());
  EXPECT_EQ(j["device"]["name"], "Made-up GPU 9000");
  EXPECT_DOUBLE_EQ(j["copy_bandwidth"]["gb_per_s"].get<double>(), 1000.0);
  EXPECT_EQ(j["results"].size(), 2u * 2 * 2 * 3);
  EXPECT_EQ(j["datasets"].size(), 3u);
  EXPECT_EQ(j["datasets"][2]["status"], "skipped");
  EXPECT_EQ(j["command_line"], "pointrast bench x");
}

TEST(Report, WritesThreeFilesAndNoPartials) {
  namespace fs = std::filesystem;
  fs::path dir = fs::temp_directory_path() / ("pointrast_report_" + std::to_string(::getpid())) / "sub";
  WrittenFiles files = writeReports(madeUpRun(), info(), dir);
  EXPECT_TRUE(fs::exists(files.json) && fs::exists(files.markdown) && fs::exists(files.svg));
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().string().find(".partial"), std::string::npos) << entry.path();
  std::ifstream in(files.json);
  nlohmann::json parsed = nlohmann::json::parse(in);
  EXPECT_EQ(parsed["name"], "made-up");
  fs::remove_all(dir.parent_path());
}

TEST(Report, Formatting) {
  EXPECT_EQ(sanitizeName("NVIDIA H200"), "nvidia-h200");
  EXPECT_EQ(sanitizeName("llvmpipe (LLVM 15.0.6, 256 bits)"), "llvmpipe-llvm-15-0-6-256-bits");
  EXPECT_EQ(formatMs(1234.4), "1234");
  EXPECT_EQ(formatMs(12.34), "12.3");
  EXPECT_EQ(formatMs(0.01234), "0.0123");
  EXPECT_EQ(shortCount(4'000'000), "4M");
  EXPECT_EQ(shortCount(145'000'000), "145M");
  EXPECT_EQ(shortCount(1'500'000), "1.5M");
  EXPECT_EQ(shortCount(20'000), "20k");
  EXPECT_EQ(shortCount(999), "999");
}

TEST(Suites, Paper2021SizesAndScale) {
  std::vector<Dataset> full = suiteDatasets("paper2021", 1.0, 1);
  ASSERT_EQ(full.size(), 4u);
  EXPECT_EQ(full[0].points, 4'000'000u);
  EXPECT_EQ(full[1].points, 47'000'000u);
  EXPECT_EQ(full[2].points, 145'000'000u);
  EXPECT_EQ(full[3].points, 796'000'000u);
  EXPECT_EQ(full[2].label, "retz-like (terrain, 145M)");
  std::vector<Dataset> smoke = suiteDatasets("paper2021", 0.001, 1);
  EXPECT_EQ(smoke[0].points, 4'000u);
  EXPECT_EQ(smoke[3].points, 796'000u);
  EXPECT_THROW(suiteDatasets("paper1999", 1.0, 1), InputError);
  EXPECT_THROW(suiteDatasets("paper2021", 0.0, 1), InputError);
  EXPECT_THROW(suiteDatasets("paper2021", 1.0, 1, {"nowhere=/x.las"}), InputError);
  EXPECT_THROW(suiteDatasets("paper2021", 1.0, 1, {"retz=/does/not/exist.las"}), InputError);
  EXPECT_THROW(suiteDatasets("paper2021", 1.0, 1, {"retz.las"}), InputError);
}

} // namespace

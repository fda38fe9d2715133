// The 2022 batch methods through the binary (validation layer on): render --method batch* with its
// statistics in --json, --precision, the method list in --help, and the paper2022 suite at a smoke scale.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"

namespace {

namespace fs = std::filesystem;
using Result = pointrast::test::CliResult;
using pointrast::test::slurp;

Result run(const std::string& args) {
  return pointrast::test::runPointrast(args);
}

int errorLines(const std::string& err) {
  int lines = 0;
  std::istringstream in(err);
  std::string line;
  while (std::getline(in, line))
    lines += line.rfind("pointrast:", 0) == 0;
  return lines;
}

TEST(BatchCli, RenderPrintsBatchStatistics) {
  fs::path dir = pointrast::test::cliTempDir();
  for (std::string method : {"batch", "batch-prefetch", "batch-hqs"}) {
    for (std::string precision : {"adaptive", "3"}) {
      fs::path png = dir / (method + "-" + precision + ".png");
      Result r = run("render terrain --points 50k --order morton --method " + method + " --precision " +
                     precision + " --width 160 --height 100 --frames 2 --json -q -o " + png.string());
      ASSERT_EQ(r.exitCode, 0) << r.err;
      nlohmann::json j = nlohmann::json::parse(r.out);
      EXPECT_EQ(j["method"], method);
      EXPECT_EQ(j["precision"], precision);
      const auto& s = j["batch_stats"];
      EXPECT_EQ(s["batches_processed"], 5); // 50,000 points in batches of 10,240
      EXPECT_GT(s["points_rendered"].get<uint64_t>(), 0u);
      EXPECT_EQ(s["points_processed"].get<uint64_t>(), s["points_by_words"][0].get<uint64_t>() +
                                                           s["points_by_words"][1].get<uint64_t>() +
                                                           s["points_by_words"][2].get<uint64_t>());
      if (precision == "3") {
        EXPECT_EQ(s["points_by_words"][2], s["points_processed"]);
      }
      EXPECT_EQ(s["points_blended"].get<uint64_t>() > 0, method == "batch-hqs");
      EXPECT_TRUE(fs::exists(png));
    }
  }
  // Separately uploaded scenes in parts of their own.
  Result parts =
      run("render terrain --points 50k --method batch --parts 3 --width 160 --height 100 --frames 1 "
          "--json -q -o " +
          (dir / "parts.png").string());
  ASSERT_EQ(parts.exitCode, 0) << parts.err;
  EXPECT_EQ(nlohmann::json::parse(parts.out)["batch_stats"]["batches_processed"], 6); // 2 per scene
  // The 2021 methods print no batch statistics.
  Result atomic = run("render terrain --points 50k --width 160 --height 100 --frames 1 --json -q -o " +
                      (dir / "atomic.png").string());
  ASSERT_EQ(atomic.exitCode, 0) << atomic.err;
  EXPECT_FALSE(nlohmann::json::parse(atomic.out).contains("batch_stats"));
}

TEST(BatchCli, HelpListsTheMethodsAndBadPrecisionIsOneLine) {
  Result help = run("render --help");
  EXPECT_EQ(help.exitCode, 0);
  for (const char* text : {"batch-prefetch", "batch-hqs", "--precision", "  batch  "})
    EXPECT_NE(help.out.find(text), std::string::npos) << text;
  fs::path png = pointrast::test::cliTempDir() / "bad.png";
  for (std::string args :
       {"--method batch --precision 4", "--method batch --precision high", "--method earlyz --precision 3"}) {
    Result r = run("render terrain --points 1000 " + args + " -o " + png.string());
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_EQ(errorLines(r.err), 1) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(png)) << args;
  }
  Result bench = run("bench --help");
  EXPECT_NE(bench.out.find("paper2022"), std::string::npos);
}

TEST(BatchCli, Paper2022SuiteSmokeScale) {
  fs::path out = pointrast::test::cliTempDir() / "paper2022";
  Result r =
      run("bench --suite paper2022 --scale 0.0001 --frames 1 --width 64 --height 40 --copy-size 16M -q "
          "--out " +
          out.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::ifstream in(out / "paper2022-scale0.0001.json");
  ASSERT_TRUE(in);
  nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["datasets"].size(), 5u);
  EXPECT_EQ(j["datasets"][3]["points"], 100000);
  EXPECT_EQ(j["settings"]["width"], 64) << "--width overrides the suite's 2560";
  // (3 data sets x 1 view + scan529m x 2 views + tls-order x 2 orders x 2 views) x 6 methods, and the 2 LOD
  // methods once per data set and view (on its octree, whatever the orders): 7 x 2.
  EXPECT_EQ(j["results"].size(), (3 + 2 + 4) * 6u + 7 * 2u);
  size_t withStats = 0;
  for (const auto& result : j["results"])
    withStats += result.contains("batch_stats") && !result.contains("lod_stats");
  EXPECT_EQ(withStats, (3 + 2 + 4) * 3u);
  std::string md = slurp(out / "paper2022-scale0.0001.md");
  EXPECT_NE(md.find("| data set | order | hw-points | batch | batch-prefetch | batch-hqs | dedup | hqs | lod | "
                    "lod-hqs |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| tls-order (tls, 10k) | original |"), std::string::npos) << md;
  EXPECT_NE(md.find("## Batch statistics per frame"), std::string::npos) << md;
}

} // namespace

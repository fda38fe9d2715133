// `pointrast bench` as a user meets it: a tiny matrix end to end through the binary (validation layer
// on), its three report files, --json lines, the suite's smoke scale, and one-line usage errors.
// Timings are never asserted: lavapipe on a shared CI machine gives no stable figure.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "test_data.h"
#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using Result = pointrast::test::CliResult;
using pointrast::test::slurp;

fs::path tempDir() {
  return pointrast::test::cliTempDir();
}
Result run(const std::string& args) {
  return pointrast::test::runPointrast(args);
}

const char* kTiny = "bench terrain --points 20k --methods atomicmin,earlyz --orders original,morton "
                    "--frames 2 --width 160 --height 100 --copy-size 16M";

TEST(BenchCli, TinyMatrixWritesJsonMarkdownAndSvg) {
  fs::path out = tempDir() / "tiny";
  Result r = run(std::string(kTiny) + " --views overview,outside --out " + out.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("[8/8] terrain-20k / morton / outside / earlyz: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("copy bandwidth: "), std::string::npos) << r.err;

  std::ifstream in(out / "terrain-20k.json");
  ASSERT_TRUE(in) << "no terrain-20k.json in " << out;
  nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_GT(j["copy_bandwidth"]["gb_per_s"].get<double>(), 0.0);
  EXPECT_FALSE(j["device"]["name"].get<std::string>().empty());
  EXPECT_FALSE(j["date"].get<std::string>().empty());
  EXPECT_NE(j["command_line"].get<std::string>().find("--methods atomicmin,earlyz"), std::string::npos);
  ASSERT_EQ(j["results"].size(), 8u);
  for (const auto& result : j["results"]) {
    EXPECT_EQ(result["status"], "ok") << result.dump();
    EXPECT_EQ(result["points"], 20000);
    EXPECT_EQ(result["frames"], 2);
    EXPECT_GT(result["median_ms"].get<double>(), 0.0);
    EXPECT_LE(result["min_ms"].get<double>(), result["median_ms"].get<double>());
    EXPECT_GE(result["max_ms"].get<double>(), result["median_ms"].get<double>());
    EXPECT_GT(result["effective_gb_per_s"].get<double>(), 0.0);
    EXPECT_GT(result["copy_fraction"].get<double>(), 0.0);
  }

  std::string md = slurp(out / "terrain-20k.md");
  EXPECT_NE(md.find("## overview: median GPU time per frame, ms"), std::string::npos) << md;
  EXPECT_NE(md.find("## outside: median GPU time per frame, ms"), std::string::npos) << md;
  EXPECT_NE(md.find("| data set | order | atomicmin | earlyz |"), std::string::npos) << md;
  EXPECT_NE(md.find("| terrain-20k | original |"), std::string::npos) << md;
  EXPECT_NE(md.find("| terrain-20k | morton |"), std::string::npos) << md;
  EXPECT_EQ(md.find("n/a"), std::string::npos) << md;

  std::string svg = slurp(out / "terrain-20k.svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_EQ(entry.path().extension().string().find("partial"), std::string::npos) << entry.path();
}

TEST(BenchCli, JsonPrintsOneObjectPerResult) {
  Result r = run(std::string(kTiny) + " --json --views outside --out " + (tempDir() / "json").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int count = 0;
  while (std::getline(lines, line)) {
    nlohmann::json j = nlohmann::json::parse(line);
    EXPECT_EQ(j["view"], "outside");
    EXPECT_TRUE(j.contains("device"));
    EXPECT_GT(j["copy_gb_per_s"].get<double>(), 0.0);
    ++count;
  }
  EXPECT_EQ(count, 4);
}

TEST(BenchCli, SuiteSmokeScaleRunsEveryDataSet) {
  fs::path out = tempDir() / "suite";
  Result r =
      run("bench --suite paper2021 --scale 0.0001 --methods atomicmin --orders morton --views overview "
          "--frames 1 --width 64 --height 40 --copy-size 16M --out " +
          out.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::ifstream in(out / "paper2021-scale0.0001.json");
  ASSERT_TRUE(in);
  nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["datasets"].size(), 4u);
  EXPECT_EQ(j["datasets"][0]["name"], "banyunibo-like");
  EXPECT_EQ(j["datasets"][3]["points"], 79600);
  EXPECT_EQ(j["results"].size(), 4u);
  std::string md = slurp(out / "paper2021-scale0.0001.md");
  EXPECT_NE(md.find("| endeavor-like (tls, 79.6k) | morton |"), std::string::npos) << md;
  EXPECT_NE(r.err.find("retz-like (terrain, 14.5k): needs "), std::string::npos) << r.err;
}

TEST(BenchCli, HelpAndUsageErrors) {
  Result help = run("bench --help");
  EXPECT_EQ(help.exitCode, 0);
  EXPECT_NE(help.out.find("Example"), std::string::npos);
  EXPECT_NE(help.out.find("paper2021"), std::string::npos);
  fs::path out = tempDir() / "errors";
  for (std::string args :
       {"--methods nope", "--orders zigzag", "--views inside", "--frames 0", "--width 0",
        "--methods atomicmin,,earlyz", "--scale 0.1", "--suite paper1999", "nothing-here.las",
        "--suite paper2021 --points 10k", "--suite paper2021 --scale -1", "--name a/b"}) {
    Result r = run("bench terrain --points 1000 " + args + " --out " + out.string());
    if (args.rfind("--suite", 0) == 0 || args == "nothing-here.las")
      r = run("bench " + args + " --out " + out.string());
    EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
    int errorLines = 0;
    std::istringstream lines(r.err);
    std::string line;
    while (std::getline(lines, line))
      errorLines += line.rfind("pointrast:", 0) == 0;
    EXPECT_EQ(errorLines, 1) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << args << ": a failed run writes nothing";
  }
}

} // namespace

TEST(BenchCli, AGpuThatStopsMakingProgressIsOneClearErrorNotAHang) {
  // POINTRAST_GPU_TIMEOUT_S makes every submission "time out": the run must end with exit 1, one line
  // naming the fault, no crash, no validation error, and no half-written report.
  fs::path out = tempDir() / "fault";
  fs::remove_all(out);
  setenv("POINTRAST_GPU_TIMEOUT_S", "0.000001", 1);
  Result r =
      run("bench terrain --points 20k --methods atomicmin --orders original --views overview --frames 2 "
          "--width 160 --height 100 --copy-size 16M -q --out " +
          out.string());
  unsetenv("POINTRAST_GPU_TIMEOUT_S");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("did not finish a submission"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("validation error"), std::string::npos) << r.err;
  if (fs::exists(out))
    for (const auto& entry : fs::directory_iterator(out))
      ADD_FAILURE() << "nothing should be written, found " << entry.path();
}

namespace {

// Lines of stderr that are pointrast's own error lines.
int errorLines(const std::string& err) {
  int lines = 0;
  std::istringstream in(err);
  for (std::string line; std::getline(in, line);)
    lines += line.rfind("pointrast:", 0) == 0;
  return lines;
}

} // namespace

TEST(BenchCli, ALostDeviceKeepsWhatWasMeasuredAndIsOneErrorLine) {
  // POINTRAST_INJECT_DEVICE_LOST=6: the sixth submission (after the copy bandwidth, the upload and the
  // first combinations) and every later one fail with VK_ERROR_DEVICE_LOST, as a driver reset would.
  fs::path out = tempDir() / "lost";
  fs::remove_all(out);
  setenv("POINTRAST_INJECT_DEVICE_LOST", "6", 1);
  Result r = run("bench terrain --points 20k --methods atomicmin,earlyz,reduce,reduce-earlyz,dedup-ballot,"
                 "busyloop,justset --orders original --views overview --frames 2 --width 160 --height 100 "
                 "--copy-size 16M --budget 0 -q --out " +
                 out.string());
  unsetenv("POINTRAST_INJECT_DEVICE_LOST");
  EXPECT_FALSE(r.signaled) << r.err;
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(errorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("device was lost (VK_ERROR_DEVICE_LOST from vkQueueSubmit)"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find(".cpp"), std::string::npos) << "no source locations in a device fault: " << r.err;
  ASSERT_TRUE(fs::exists(out / "terrain-20k.json")) << r.err;
  nlohmann::json report = nlohmann::json::parse(slurp(out / "terrain-20k.json"));
  int ok = 0, faulted = 0;
  for (const auto& result : report["results"]) {
    ok += result["status"] == "ok";
    faulted += result["status"] == "device-fault";
  }
  EXPECT_GE(ok, 1) << "what was measured before the fault is kept";
  EXPECT_EQ(faulted, 1);
  EXPECT_LT(report["results"].size(), 7u) << "nothing runs after the fault";
  EXPECT_NE(slurp(out / "terrain-20k.md").find("Stopped early"), std::string::npos);
}

TEST(BenchCli, ALostDeviceInTheLodSuiteKeepsWhatWasMeasuredAndIsOneErrorLine) {
  // The first submission after the first measured result fails (result+1): node uploads are submissions
  // too and come from reader threads, so a count from the process's start would land at a point that
  // depends on their timing.
  fs::path dir = tempDir() / "lost-lod";
  fs::remove_all(dir);
  setenv("POINTRAST_INJECT_DEVICE_LOST", "result+1", 1);
  Result r = run("bench --suite lod --views overview --flight-frames 6 --jumps 2 --scale 0.0001 --frames 1 "
                 "--width 160 --height 100 --copy-size 16M --budget 0 -q --octree-cache " +
                 (dir / "octrees").string() + " --out " + (dir / "out").string());
  unsetenv("POINTRAST_INJECT_DEVICE_LOST");
  EXPECT_FALSE(r.signaled) << r.err;
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(errorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("device was lost"), std::string::npos) << r.err;
  const fs::path json = dir / "out" / "lod-scale0.0001.json";
  ASSERT_TRUE(fs::exists(json)) << r.err;
  nlohmann::json report = nlohmann::json::parse(slurp(json));
  EXPECT_NE(report["stopped"].get<std::string>().find("device was lost"), std::string::npos);
  int ok = 0, faulted = 0;
  for (const char* part : {"sweeps", "streams"})
    for (const auto& result : report[part]) {
      ok += result["status"] == "ok";
      faulted += result["status"] == "device-fault";
    }
  EXPECT_GE(ok, 1) << "what was measured before the fault is kept";
  EXPECT_EQ(faulted, 1) << "nothing runs after the fault";
}

TEST(BenchCli, ALostDeviceInRenderIsOneLineAndNoImage) {
  fs::path png = tempDir() / "lost.png";
  fs::remove(png);
  setenv("POINTRAST_INJECT_DEVICE_LOST", "1", 1);
  Result r = run("render terrain --points 20k --width 160 --height 100 -q -o " + png.string());
  unsetenv("POINTRAST_INJECT_DEVICE_LOST");
  EXPECT_FALSE(r.signaled) << r.err;
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(errorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("device was lost"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(png));
}

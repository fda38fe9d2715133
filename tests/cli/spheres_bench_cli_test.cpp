// `pointrast bench --suite spheres2023` as a user meets it: the whole matrix at a tiny scale through the
// binary (validation layer on), its three report files, --json lines for a part of the matrix, and one-line
// usage errors. Timings are never asserted: lavapipe on a shared CI machine gives no stable figure.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::cliTempDir;
using pointrast::test::runPointrast;
using pointrast::test::slurp;

TEST(SpheresBenchCli, TinySuiteRunsTheWholeMatrix) {
  fs::path out = cliTempDir() / "spheres2023";
  fs::remove_all(out);
  CliResult r = runPointrast("bench --suite spheres2023 --scale 0.00001 --cameras 2 --frames 1 --width 96 "
                             "--height 54 --copy-size 16M --out " +
                             out.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("laser-like (particles-laser, 3.1k): needs "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("laser-like (particles-laser, 3.1k): layout xyz skipped: "), std::string::npos)
      << r.err;
  // Progress: the last line counts every combination.
  const std::string err = r.err;
  const std::regex counter(R"(\[(\d+)/(\d+)\] )");
  std::smatch last;
  size_t progressLines = 0;
  for (std::sregex_iterator it(err.begin(), err.end(), counter), end; it != end; ++it) {
    last = *it;
    ++progressLines;
  }
  ASSERT_GT(progressLines, 0u) << r.err;
  EXPECT_EQ(last[1], last[2]) << r.err;

  std::ifstream in(out / "spheres2023-scale1e-05.json");
  ASSERT_TRUE(in) << "no spheres2023-scale1e-05.json in " << out;
  nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j["datasets"].size(), 4u);
  EXPECT_EQ(j["datasets"][0]["name"], "laser-like");
  EXPECT_EQ(j["datasets"][1]["points"], 1000);
  EXPECT_EQ(j["datasets"][3]["points"], 2000);
  EXPECT_EQ(j["datasets"][0]["cameras"]["short"].size(), 2u);
  EXPECT_EQ(j["results"].size(), progressLines);
  std::set<std::string> methods, layouts;
  for (const auto& result : j["results"]) {
    methods.insert(result["method"].get<std::string>());
    layouts.insert(result["layout"].get<std::string>());
    const std::string method = result["method"];
    if (method == "sphere-compute" || (method == "sphere-triangles" && !result["conservative"].get<bool>())) {
      EXPECT_EQ(result["status"], "ok") << result.dump();
      EXPECT_EQ(result["cameras"], 2);
      EXPECT_GT(result["median_ms"].get<double>(), 0.0);
    }
    if (result["status"] != "ok") {
      EXPECT_FALSE(result["reason"].get<std::string>().empty()) << result.dump();
    }
    if (method == "sphere-compute") {
      EXPECT_EQ(result["billboard"], "none");
    }
  }
  for (const char* m : {"sphere-compute", "sphere-points", "sphere-triangles", "sphere-strip", "sphere-geom"})
    EXPECT_EQ(methods.count(m), 1u) << m << " missing: every method of the table is measured";
  EXPECT_EQ(layouts, (std::set<std::string>{"soa8", "vec4x2", "aos"}));

  std::string md = slurp(out / "spheres2023-scale1e-05.md");
  EXPECT_NE(md.find("## short orbit: median GPU time per frame, ms"), std::string::npos) << md;
  EXPECT_NE(md.find("## long orbit: median GPU time per frame, ms"), std::string::npos) << md;
  EXPECT_NE(md.find("| laser-like (particles-laser, 3.1k) | soa8 | sphere-compute |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| riemann-like (particles-block, 1k) | aos | sphere-strip |"), std::string::npos) << md;
  EXPECT_NE(md.find("## sphere-compute against the fastest other method"), std::string::npos) << md;
  std::string svg = slurp(out / "spheres2023-scale1e-05.svg");
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_EQ(entry.path().extension().string().find("partial"), std::string::npos) << entry.path();
}

TEST(SpheresBenchCli, JsonLinesForAPartOfTheMatrix) {
  fs::path out = cliTempDir() / "spheres_json";
  CliResult r =
      runPointrast("bench --suite spheres2023 --scale 0.00001 --methods sphere-compute,sphere-strip "
                   "--layouts aos --billboards camera --conservative off --orbits long --cameras 1 "
                   "--frames 1 --width 64 --height 36 --copy-size 16M --json --name part --out " +
                   out.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int count = 0;
  while (std::getline(lines, line)) {
    nlohmann::json j = nlohmann::json::parse(line);
    EXPECT_EQ(j["orbit"], "long");
    EXPECT_EQ(j["layout"], "aos");
    EXPECT_EQ(j["billboard"], j["method"] == "sphere-strip" ? "camera" : "none");
    EXPECT_EQ(j["status"], "ok") << line;
    EXPECT_TRUE(j.contains("device"));
    ++count;
  }
  EXPECT_EQ(count, 4 * 2) << "four data sets x two methods";
  EXPECT_TRUE(fs::exists(out / "part.json"));
}

TEST(SpheresBenchCli, UsageErrorsAreOneLine) {
  fs::path out = cliTempDir() / "spheres_errors";
  fs::remove_all(out);
  for (std::string args :
       {"--suite spheres2023 --orders morton", "--suite spheres2023 --views overview",
        "--suite spheres2023 --methods atomicmin", "--suite spheres2023 --layouts cubes",
        "--suite spheres2023 --billboards round", "--suite spheres2023 --conservative maybe",
        "--suite spheres2023 --orbits medium", "--suite spheres2023 --cameras 0",
        "--suite spheres2023 --scale 0", "--suite spheres2023 laser=/data/laser.mmpld",
        "terrain --points 1000 --layouts soa8", "terrain --points 1000 --orbits long"}) {
    CliResult r = runPointrast("bench " + args + " --out " + out.string());
    EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
    EXPECT_FALSE(r.signaled) << args;
    int errorLines = 0;
    std::istringstream lines(r.err);
    std::string line;
    while (std::getline(lines, line))
      errorLines += line.rfind("pointrast:", 0) == 0;
    EXPECT_EQ(errorLines, 1) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << args << ": a failed run writes nothing";
  }
  CliResult help = runPointrast("bench --help");
  EXPECT_NE(help.out.find("spheres2023"), std::string::npos);
  EXPECT_NE(help.out.find("laser (particles-laser, 306 M"), std::string::npos) << help.out;
}

TEST(SpheresBenchCli, AGpuThatStopsMakingProgressIsOneClearError) {
  fs::path out = cliTempDir() / "spheres_fault";
  fs::remove_all(out);
  setenv("POINTRAST_GPU_TIMEOUT_S", "0.000001", 1);
  CliResult r = runPointrast("bench --suite spheres2023 --scale 0.00001 --methods sphere-compute --cameras 1 "
                             "--frames 1 --width 64 --height 36 --copy-size 16M -q --out " +
                             out.string());
  unsetenv("POINTRAST_GPU_TIMEOUT_S");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("did not finish a submission"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("validation error"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "spheres2023-scale1e-05.json"));
}

} // namespace

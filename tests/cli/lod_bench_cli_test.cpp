// The LOD benchmarks as a user runs them, through the binary on lavapipe (validation layer on), at a tiny
// scale: paper2022's LOD methods next to batch-prefetch on one data set, the lod suite's sweeps and
// streaming, one octree cache shared by both (built by the first run, reused by the others, built again
// when damaged), and one-line refusals of wrong options. Timings are never asserted.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using pointrast::test::slurp;

// aerial1g at scale 0.0001: 100 k generated terrain points, the key both suites file its octree under.
const char* kScale = "--scale 0.0001";
const char* kKey = "aerial1g-like-100000-seed1";
const char* kSmall = "--frames 1 --width 160 --height 100 --copy-size 16M --budget 0";

nlohmann::json readJson(const fs::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << "no " << path;
  return in ? nlohmann::json::parse(in) : nlohmann::json{};
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
    ++n;
  return n;
}

CliResult paper2022(const fs::path& cache, const fs::path& out) {
  return runPointrast(std::string("bench --suite paper2022 --datasets aerial1g --methods "
                                  "batch-prefetch,lod,lod-hqs ") +
                      kScale + " " + kSmall + " --octree-cache " + cache.string() + " --out " + out.string());
}

CliResult lodSuite(const fs::path& cache, const fs::path& out) {
  return runPointrast(std::string("bench --suite lod --views overview --flight-frames 6 --jumps 2 ") +
                      kScale + " " + kSmall + " --octree-cache " + cache.string() + " --out " + out.string());
}

TEST(LodBenchCli, BothSuitesShareOneOctreeCache) {
  const fs::path dir = pointrast::test::cliTempDir() / "lod-bench";
  fs::remove_all(dir);
  const fs::path cache = dir / "octrees";

  // paper2022 on aerial1g only: batch-prefetch in Morton order, the LOD methods once on the octree it builds.
  CliResult r = paper2022(cache, dir / "p1");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(count(r.err, "octree cache: building " + (cache / kKey).string()), 1u) << r.err;
  EXPECT_TRUE(fs::is_directory(cache / kKey));
  const nlohmann::json built = readJson(cache / (std::string(kKey) + ".json"));
  EXPECT_EQ(built["points"], 100000);
  EXPECT_NE(built["phases"].get<std::string>().find("records"), std::string::npos) << built.dump();
  EXPECT_NE(built["phases"].get<std::string>().find("commit"), std::string::npos) << built.dump();
  nlohmann::json j = readJson(dir / "p1" / "paper2022-scale0.0001.json");
  ASSERT_EQ(j["results"].size(), 3u) << j["results"].dump();
  for (const nlohmann::json& result : j["results"]) {
    EXPECT_EQ(result["status"], "ok") << result.dump();
    EXPECT_EQ(result["dataset"], "aerial1g-like");
  }
  ASSERT_EQ(j["octrees"].size(), 1u);
  EXPECT_FALSE(j["octrees"][0]["reused"].get<bool>());
  EXPECT_EQ(j["octrees"][0]["points"], 100000);
  std::string md = slurp(dir / "p1" / "paper2022-scale0.0001.md");
  EXPECT_NE(md.find("## LOD statistics per frame"), std::string::npos) << md;
  EXPECT_NE(md.find("| aerial1g-like (terrain, 100k) | overview | lod |"), std::string::npos) << md;

  // The lod suite finds the same octree (same data set, size and seed) and sweeps and streams it.
  r = lodSuite(cache, dir / "l1");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err.find("octree cache: building"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(from the cache)"), std::string::npos) << r.err;
  j = readJson(dir / "l1" / "lod-scale0.0001.json");
  EXPECT_EQ(j["sweeps"].size(), 11u) << "6 point budgets and 5 minimum node sizes, one view";
  for (const nlohmann::json& sweep : j["sweeps"])
    EXPECT_EQ(sweep["status"], "ok") << sweep.dump();
  ASSERT_EQ(j["streams"].size(), 1u);
  EXPECT_EQ(j["streams"][0]["status"], "ok") << j["streams"][0].dump();
  EXPECT_EQ(j["streams"][0]["flight"]["frames"], 6);
  EXPECT_EQ(j["streams"][0]["jumps"].size(), 2u);
  ASSERT_EQ(j["octrees"].size(), 1u);
  EXPECT_TRUE(j["octrees"][0]["reused"].get<bool>());
  EXPECT_EQ(j["octrees"][0]["phases"], built["phases"]) << "a reused octree reports its build";
  md = slurp(dir / "l1" / "lod-scale0.0001.md");
  EXPECT_NE(md.find("## Render time against the point budget"), std::string::npos) << md;
  EXPECT_NE(md.find("Targets: every frame of the flight at >= 60 fps"), std::string::npos) << md;
  EXPECT_TRUE(fs::exists(dir / "l1" / "lod-scale0.0001.svg"));

  // paper2022 again: reused.
  r = paper2022(cache, dir / "p2");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err.find("octree cache: building"), std::string::npos) << r.err;
  j = readJson(dir / "p2" / "paper2022-scale0.0001.json");
  ASSERT_EQ(j["octrees"].size(), 1u);
  EXPECT_TRUE(j["octrees"][0]["reused"].get<bool>());

  // A truncated octree.bin (a full disk, a copy cut short) is found and the octree built again; so is an
  // entry whose build record is gone; a killed build's leftovers are removed.
  fs::resize_file(cache / kKey / "octree.bin", fs::file_size(cache / kKey / "octree.bin") / 2);
  fs::create_directories(cache / (std::string(kKey) + ".partial-999999999"));
  r = lodSuite(cache, dir / "l2");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("is damaged (its files are not those its build wrote); building it again"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("left by a build that was stopped"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(cache / (std::string(kKey) + ".partial-999999999")));
  EXPECT_EQ(count(r.err, "octree cache: building"), 1u) << r.err;
  fs::remove(cache / (std::string(kKey) + ".json"));
  r = paper2022(cache, dir / "p3");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("is damaged (no build record"), std::string::npos) << r.err;
  j = readJson(dir / "p3" / "paper2022-scale0.0001.json");
  for (const nlohmann::json& result : j["results"])
    EXPECT_EQ(result["status"], "ok") << result.dump();
  for (const auto& entry : fs::directory_iterator(cache))
    EXPECT_EQ(entry.path().filename().string().find("partial"), std::string::npos) << entry.path();
  fs::remove_all(dir);
}

TEST(LodBenchCli, WrongOptionsFailWithOneLine) {
  const fs::path dir = pointrast::test::cliTempDir() / "lod-bench-wrong";
  struct Case {
    std::string args, message;
  };
  const Case cases[] = {
      {"bench --suite paper2022 --datasets aerial2g --scale 0.0001",
       "--datasets: 'aerial2g' is no data set of suite paper2022 (scan69m, aerial279m, scan529m, aerial1g, "
       "tls-order)"},
      {"bench terrain --points 1k --datasets aerial1g", "--datasets picks data sets of a --suite"},
      {"bench --suite paper2022 --jumps 3 --scale 0.0001",
       "--flight-frames and --jumps apply to --suite lod"},
      {"bench --suite lod --flight-frames 0 --scale 0.0001", "--flight-frames must be at least 1"},
      {"bench --suite lod --orders morton --scale 0.0001", "--orders do not apply to --suite lod"},
      {"bench --suite lod --methods batch --scale 0.0001", "--suite lod measures the method lod"},
  };
  for (const Case& c : cases) {
    const CliResult r = runPointrast(c.args + " --out " + dir.string());
    EXPECT_EQ(r.exitCode, 1) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(count(r.err, "\n"), 1u) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir)) << c.args;
  }
  // A cache folder that cannot be made: the LOD methods say why, and a run of them alone measured nothing.
  const CliResult r = lodSuite("/proc/no-octrees-here", dir);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("/proc/no-octrees-here: cannot create the octree cache folder"), std::string::npos)
      << r.err;
  EXPECT_FALSE(r.signaled);
}

} // namespace

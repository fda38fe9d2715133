// The LOD methods through the CLI: `render DIR --method lod|lod-hqs` on a Potree 2.0 folder (empty inner
// nodes included) draws every point with --min-node-px 0, the same image with a node cache far smaller than
// the octree (drawn in passes), reports its statistics in --json; wrong inputs and options, and an octree
// damaged where only streaming finds it, fail with one line and exit 1.
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "io/potree_test_util.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using namespace pointrast;

fs::path dirOf(const std::string& name) {
  return pointrast::test::cliTempDir() / ("lod-" + name);
}

// Hierarchy chunks of 2 levels: the chunks below level 2 are read only when streaming reaches them.
potreetest::Tree writeOctree(const std::string& name) {
  const potreetest::Tree tree = potreetest::makeTree({.points = 8000, .depth = 4, .seed = 5});
  fs::remove_all(dirOf(name));
  io::PotreeWriteOptions options;
  options.hierarchyStepSize = 2;
  potreetest::writeTree(tree, dirOf(name), options);
  return tree;
}

void expectOneErrorLine(const CliResult& r, const std::string& args, const std::string& says) {
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  int lines = 0;
  for (size_t at = r.err.find("pointrast:"); at != std::string::npos; at = r.err.find("pointrast:", at + 1))
    ++lines;
  EXPECT_EQ(lines, 1) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
}

const std::string kView = " --width 200 --height 120 --frames 1 --json -q";

TEST(LodCli, RendersEveryPointOfAnOctreeInOnePassOrMany) {
  const potreetest::Tree tree = writeOctree("render");
  const fs::path png = pointrast::test::cliTempDir() / "lod.png";
  const std::string base = "render " + dirOf("render").string() + " -o " + png.string() + kView;
  const CliResult whole = runPointrast(base + " --method lod --min-node-px 0");
  ASSERT_EQ(whole.exitCode, 0) << whole.err;
  const nlohmann::json w = nlohmann::json::parse(whole.out);
  EXPECT_EQ(w["method"], "lod");
  EXPECT_EQ(w["points"], tree.points());
  EXPECT_EQ(w["octree_points"], tree.points());
  EXPECT_EQ(w["lod_stats"]["points_drawn"], tree.points());
  EXPECT_EQ(w["lod_stats"]["passes"], 1);
  EXPECT_TRUE(w["lod_stats"]["converged"]);
  EXPECT_GT(w["lod_stats"]["bytes_streamed"], 0);
  EXPECT_GT(w["batch_stats"]["batches_processed"], 0);
  EXPECT_TRUE(w["clocks_settled"].is_boolean()) << w; // settled, or not where the GPU's clocks never did
  EXPECT_TRUE(fs::exists(png));

  // A node cache of 192 KiB (three pages): many passes, the same image.
  const CliResult parts = runPointrast(base + " --method lod --min-node-px 0 --gpu-memory 192k");
  ASSERT_EQ(parts.exitCode, 0) << parts.err;
  const nlohmann::json p = nlohmann::json::parse(parts.out);
  EXPECT_GT(p["lod_stats"]["passes"], 1);
  EXPECT_EQ(p["lod_stats"]["cache_bytes"], 3 * 65536);
  EXPECT_TRUE(p["clocks_settled"].is_boolean()) << p;
  EXPECT_EQ(p["image_hash"], w["image_hash"]);

  const CliResult hqs = runPointrast(base + " --method lod-hqs --min-node-px 0 --gpu-memory 192k");
  ASSERT_EQ(hqs.exitCode, 0) << hqs.err;
  EXPECT_EQ(nlohmann::json::parse(hqs.out)["batch_stats"]["points_blended"].get<uint64_t>() > 0, true);

  // LOD culling at the default 100 px draws fewer points; a budget fewer still.
  const CliResult culled = runPointrast(base + " --method lod");
  ASSERT_EQ(culled.exitCode, 0) << culled.err;
  const nlohmann::json c = nlohmann::json::parse(culled.out);
  EXPECT_LT(c["points"], tree.points());
  EXPECT_EQ(c["min_node_px"], 100.0);
  const CliResult budget = runPointrast(base + " --method lod --min-node-px 0 --point-budget 1000");
  ASSERT_EQ(budget.exitCode, 0) << budget.err;
  EXPECT_LE(nlohmann::json::parse(budget.out)["points"], 1000);
}

TEST(LodCli, WrongInputsAndOptionsFailWithOneLine) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  writeOctree("wrong");
  const fs::path png = pointrast::test::cliTempDir() / "wrong.png";
  const std::string out = " -o " + png.string() + " -q";
  const std::string octree = dirOf("wrong").string();
  const std::string las = (pointrast::test::dataDir() / "las" / "autzen_trim.las").string();
  const std::pair<std::string, std::string> cases[] = {
      {"render terrain --method lod" + out, "is a generated scene; lod draws octrees"},
      {"render " + octree + " --method lod --gpu-memory 12x" + out, "--gpu-memory expects a size"},
      {"render " + octree + " --method lod --min-node-px -1" + out, "--min-node-px must be 0 or more"},
      {"render " + octree + " --method lod --order morton" + out, "do not apply to lod"},
      {"render " + las + " --min-node-px 3" + out, "apply to the LOD methods (lod and lod-hqs)"},
      {"render " + octree + " --method lod --gpu-memory 1k" + out, "holds no page of the node cache"},
  };
  for (const auto& [args, says] : cases) {
    fs::remove(png);
    expectOneErrorLine(runPointrast(args), args, says);
    EXPECT_FALSE(fs::exists(png)) << args;
  }
}

// A cloud file drawn with lod opens as the viewers open it: built into the octree cache once, then
// streamed; the frame is the one of the octree `pointrast lod` builds from the same file.
TEST(LodCli, ACloudFileDrawnWithLodIsBuiltIntoTheCacheOnceAndEqualsItsOctree) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const fs::path cache = pointrast::test::cliTempDir() / "lod-cache";
  const fs::path tree = pointrast::test::cliTempDir() / "lod-cache-tree";
  fs::remove_all(cache);
  fs::remove_all(tree);
  const std::string las = (pointrast::test::dataDir() / "las" / "autzen_trim.las").string();
  const std::string png = (pointrast::test::cliTempDir() / "lod-cache.png").string();
  const std::string env = "env XDG_CACHE_HOME=" + cache.string() + " ";
  const std::string draw = " --method lod --min-node-px 20 --width 160 --height 120 --json -o " + png;
  auto run = [&](const std::string& args) {
    const std::string command = env + "'" + pointrast::test::pointrastBinary() + "' " + args + " 2>&1";
    std::string output;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return std::pair<int, std::string>{-1, ""};
    char buffer[4096];
    for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;)
      output.append(buffer, n);
    const int status = pclose(pipe);
    return std::pair<int, std::string>{WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
  };
  auto hashOf = [](const std::string& output) {
    const size_t at = output.find("\"image_hash\":\"");
    return at == std::string::npos ? std::string() : output.substr(at + 14, 16);
  };
  const auto first = run("render '" + las + "'" + draw);
  ASSERT_EQ(first.first, 0) << first.second;
  EXPECT_NE(first.second.find("octree cache: building"), std::string::npos) << first.second;
  const auto second = run("render '" + las + "'" + draw);
  ASSERT_EQ(second.first, 0) << second.second;
  EXPECT_EQ(second.second.find("octree cache: building"), std::string::npos) << "reused: " << second.second;
  const auto built = run("lod '" + las + "' -o '" + tree.string() + "' -q");
  ASSERT_EQ(built.first, 0) << built.second;
  const auto direct = run("render '" + tree.string() + "'" + draw);
  ASSERT_EQ(direct.first, 0) << direct.second;
  ASSERT_FALSE(hashOf(first.second).empty()) << first.second;
  EXPECT_EQ(hashOf(first.second), hashOf(direct.second));
  EXPECT_EQ(hashOf(second.second), hashOf(direct.second));
  fs::remove_all(cache);
  fs::remove_all(tree);
}

TEST(LodCli, AnOctreeDamagedWhereStreamingFindsItFailsWithOneLine) {
  writeOctree("damaged");
  const fs::path dir = dirOf("damaged"), png = pointrast::test::cliTempDir() / "damaged.png";
  // The last record of hierarchy.bin (a node of the deepest chunk, read only when streaming reaches it)
  // claims a byte range far past the end of octree.bin. Records: type, child mask, point count (u32),
  // byte offset (u64), byte size (u64): 22 bytes.
  std::vector<uint8_t> hierarchy = iotest::readBytes(dir / "hierarchy.bin");
  ASSERT_GE(hierarchy.size(), 22u);
  for (size_t k = 0; k < 8; ++k)
    hierarchy[hierarchy.size() - 8 + k] = 0x7F;
  iotest::writeBytes(dir / "hierarchy.bin", hierarchy);

  for (const std::string method : {"lod", "lod-hqs"})
    for (const std::string cache : {"", " --gpu-memory 192k"}) {
      const std::string args = "render " + dir.string() + " --method " + method + " --min-node-px 0" + cache +
                               " -o " + png.string() + " -q";
      fs::remove(png);
      expectOneErrorLine(runPointrast(args), args, (dir / "hierarchy.bin").string() + ": node r");
      EXPECT_FALSE(fs::exists(png)) << args;
    }
}

} // namespace

// `pointrast lod IN -o x.copc.laz`: a COPC file of the same octree as the Potree folder, drawn by
// `render --method lod` into the same image bit for bit (every point, and with LOD culling), `info` saying
// how its inner nodes' colors were made, and one-line errors with nothing written for bad outputs.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using pointrast::test::slurp;

fs::path fresh(const std::string& name) {
  fs::path p = pointrast::test::cliTempDir() / name;
  fs::remove_all(p);
  return p;
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

TEST(CopcLodCli, RendersAsThePotreeFolderOfTheSameBuild) {
  const fs::path dir = fresh("copc-render");
  fs::create_directories(dir);
  const std::string cloud = (dir / "t.las").string();
  ASSERT_EQ(runPointrast("generate terrain --points 30000 -o " + cloud + " -q").exitCode, 0);
  const std::string potree = (dir / "octree").string(), copc = (dir / "octree.copc.laz").string();
  const CliResult p = runPointrast("lod " + cloud + " -o " + potree + " --leaf-points 2k -q");
  ASSERT_EQ(p.exitCode, 0) << p.err;
  const CliResult c = runPointrast("lod " + cloud + " -o " + copc + " --leaf-points 2k --json");
  ASSERT_EQ(c.exitCode, 0) << c.err;
  EXPECT_NE(c.out.find("\"format\":\"copc\""), std::string::npos) << c.out;
  EXPECT_TRUE(fs::is_regular_file(copc));

  const CliResult info = runPointrast("info " + copc);
  ASSERT_EQ(info.exitCode, 0) << info.err;
  EXPECT_NE(info.out.find("inner nodes hold averaged colors"), std::string::npos) << info.out;

  const std::string view = " --method lod --width 160 --height 120 --frames 1 -q";
  for (const std::string lod : {" --min-node-px 0", ""}) {
    const fs::path a = dir / "potree.png", b = dir / "copc.png";
    const CliResult ra = runPointrast("render " + potree + " -o " + a.string() + view + lod);
    ASSERT_EQ(ra.exitCode, 0) << ra.err;
    const CliResult rb = runPointrast("render " + copc + " -o " + b.string() + view + lod);
    ASSERT_EQ(rb.exitCode, 0) << rb.err;
    const std::string pa = slurp(a), pb = slurp(b);
    EXPECT_GT(pa.size(), 100u);
    EXPECT_TRUE(pa == pb) << "the COPC file renders differently" << lod;
  }
}

TEST(CopcLodCli, BadOutputsGiveOneLineAndWriteNothing) {
  const fs::path dir = fresh("copc-wrong");
  fs::create_directories(dir);
  const std::string cloud = (dir / "t.las").string();
  ASSERT_EQ(runPointrast("generate terrain --points 2000 -o " + cloud + " -q").exitCode, 0);
  const fs::path existing = dir / "taken.copc.laz";
  std::ofstream(existing) << "not mine";
  const std::string out = (dir / "o.copc.laz").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"lod " + cloud + " -o " + (dir / "missing" / "o.copc.laz").string(), "does not exist"},
      {"lod " + cloud + " -o " + existing.string(), "already exists"},
      {"lod " + cloud + " -o " + out + " --format las", "--format expects potree or copc"},
      {"lod " + cloud + " -o " + out + " --encoding brotli", "--encoding applies to Potree output"},
      {"lod " + (dir / "none.las").string() + " -o " + out, "none.las"},
  };
  for (const auto& [args, says] : cases) {
    expectOneErrorLine(runPointrast(args + " -q"), args, says);
    EXPECT_FALSE(fs::exists(out)) << args;
  }
  EXPECT_EQ(slurp(existing), "not mine");
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_TRUE(e.path() == fs::path(cloud) || e.path() == existing) << "left behind: " << e.path();
}

} // namespace

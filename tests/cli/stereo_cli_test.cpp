// Stereo, foveated LOD and the resolve stage on octrees through the CLI: `render --stereo` writes a
// side-by-side PNG of two --width x --height eyes (or two files), for the batch methods and an octree;
// `--foveated` and the resolve stage's options and --color reach the LOD methods and their --json; wrong
// combinations fail with one line and exit 1, leaving no file.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "io/potree_test_util.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using namespace pointrast;

// Width and height from a PNG's IHDR chunk (big-endian at bytes 16 and 20).
std::pair<uint32_t, uint32_t> pngSize(const fs::path& png) {
  std::ifstream in(png, std::ios::binary);
  unsigned char header[24] = {};
  in.read(reinterpret_cast<char*>(header), sizeof header);
  auto be = [&](int at) {
    return uint32_t(header[at]) << 24 | uint32_t(header[at + 1]) << 16 | uint32_t(header[at + 2]) << 8 |
           uint32_t(header[at + 3]);
  };
  return {be(16), be(20)};
}

fs::path octree() {
  static const fs::path dir = [] {
    const fs::path d = pointrast::test::cliTempDir() / "stereo-octree";
    fs::remove_all(d);
    potreetest::writeTree(potreetest::makeTree({.points = 8000, .depth = 4, .seed = 7}), d, {});
    return d;
  }();
  return dir;
}

void expectOneErrorLine(const CliResult& r, const std::string& args, const std::string& says) {
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_EQ(r.err.find("pointrast:"), r.err.rfind("pointrast:")) << args << "\n" << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
}

const std::string kSize = " --width 64 --height 48 --frames 1 -q";

TEST(StereoCli, SideBySideOrSeparateEyesForBatchAndLodMethods) {
  const fs::path dir = pointrast::test::cliTempDir();
  const fs::path sbs = dir / "sbs.png";
  const CliResult batch = runPointrast("render terrain --points 20k --method batch --stereo -o " +
                                       sbs.string() + kSize + " --json");
  ASSERT_EQ(batch.exitCode, 0) << batch.err;
  EXPECT_EQ(pngSize(sbs), std::make_pair(128u, 48u));
  const nlohmann::json j = nlohmann::json::parse(batch.out);
  EXPECT_EQ(j["stereo"]["layout"], "side-by-side");
  EXPECT_GT(j["stereo"]["ipd"].get<double>(), 0.0) << "the 1/30 rule";

  const fs::path pair = dir / "pair.png";
  const CliResult separate = runPointrast("render terrain --points 20k --method batch-hqs --stereo --ipd 5 "
                                          "--convergence inf --stereo-layout separate -o " +
                                          pair.string() + kSize + " --json");
  ASSERT_EQ(separate.exitCode, 0) << separate.err;
  EXPECT_FALSE(fs::exists(pair));
  EXPECT_EQ(pngSize(dir / "pair-left.png"), std::make_pair(64u, 48u));
  EXPECT_EQ(pngSize(dir / "pair-right.png"), std::make_pair(64u, 48u));
  const nlohmann::json s = nlohmann::json::parse(separate.out);
  EXPECT_EQ(s["stereo"]["convergence"], "inf");
  EXPECT_EQ(s["stereo"]["ipd"], 5.0);
  EXPECT_EQ(s["output"].size(), 2u);

  const fs::path vr = dir / "vr.png";
  const CliResult lod = runPointrast("render " + octree().string() +
                                     " --method lod-hqs --stereo --foveated --fovea-radius 0.2 --dilate 1 "
                                     "--edl --color elevation -o " +
                                     vr.string() + kSize + " --json");
  ASSERT_EQ(lod.exitCode, 0) << lod.err;
  EXPECT_EQ(pngSize(vr), std::make_pair(128u, 48u));
  const nlohmann::json l = nlohmann::json::parse(lod.out);
  EXPECT_EQ(l["foveation"]["radius"], 0.2);
  EXPECT_EQ(l["foveation"]["periphery"], 3.0);
  EXPECT_EQ(l["post"]["dilate"], 1);
  EXPECT_EQ(l["color"], "elevation");
  EXPECT_TRUE(l.contains("stereo"));
}

TEST(StereoCli, WrongCombinationsFailWithOneLine) {
  const fs::path png = pointrast::test::cliTempDir() / "wrong-stereo.png";
  const std::string out = " -o " + png.string() + kSize;
  const std::string tree = octree().string();
  const std::pair<std::string, std::string> cases[] = {
      {"render terrain --points 1k --stereo" + out, "--stereo draws both eyes in one pass with the batch"},
      // Without --method the message names what to add, not the default the user never chose.
      {"render " + tree + " --stereo" + out, "name one with --method (batch-prefetch for a cloud, lod for"},
      {"render terrain --points 1k --method atomicmin --stereo" + out, "lod and lod-hqs), not atomicmin"},
      {"render terrain --points 1k --method batch --ipd 1" + out, "need --stereo"},
      {"render terrain --points 1k --method batch --stereo --ipd -1" + out, "--ipd must be a distance > 0"},
      {"render terrain --points 1k --method batch --stereo --convergence near" + out, "--convergence takes"},
      {"render terrain --points 1k --method batch --stereo --stereo-layout over-under" + out,
       "unknown --stereo-layout"},
      {"render terrain --points 1k --method batch --foveated" + out, "--foveated applies to the LOD methods"},
      {"render " + tree + " --method lod --fovea-radius 0.5" + out, "need --foveated"},
      {"render " + tree + " --method lod --foveated --fovea-periphery 0.5" + out,
       "--fovea-periphery must be"},
      {"render " + tree + " --method lod --color classification --color-range 1,2" + out,
       "--color-range applies to --color intensity and elevation"},
      {"render " + tree + " --method lod --point-size 99" + out, "point size"},
  };
  for (const auto& [args, says] : cases) {
    fs::remove(png);
    expectOneErrorLine(runPointrast(args), args, says);
    EXPECT_FALSE(fs::exists(png)) << args;
  }
}

} // namespace

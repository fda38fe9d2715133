// `pointrast render --method sphere-compute` as a user runs it: particle scenes and points drawn as
// spheres write a PNG and one JSON line; wrong combinations exit 1 with one line and leave no file.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "cli/cli_harness.h"

namespace pointrast::test {

namespace {

namespace fs = std::filesystem;

// One line on stderr, exit 1, no crash, no output file.
void expectCleanSphereFailure(const std::string& args, const fs::path& output, const std::string& says) {
  fs::remove(output);
  CliResult r = runPointrast(args);
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_NE(r.err.find(says), std::string::npos) << args << ": stderr was " << r.err;
  EXPECT_FALSE(fs::exists(output)) << args << " left " << output;
}

} // namespace

TEST(SpheresCli, RenderParticleSceneWritesPngAndJson) {
  fs::path png = cliTempDir() / "spheres.png";
  fs::remove(png);
  CliResult r = runPointrast("render particles-drops --points 20k --method sphere-compute --layout soa8 -o " +
                             png.string() + " --width 320 --height 180 --frames 2 --json -q");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  ASSERT_TRUE(fs::exists(png));
  EXPECT_EQ(slurp(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  for (const char* key : {"\"method\":\"sphere-compute\"", "\"layout\":\"soa8\"", "\"particles\":20000",
                          "\"width\":320", "\"median_ms\"", "\"large_chunks\"", "\"image_hash\""})
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " missing in " << r.out;
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << "one JSON line: " << r.out;
}

TEST(SpheresCli, PointsDrawnAsSpheresNeedARadius) {
  fs::path png = cliTempDir() / "terrain_spheres.png";
  fs::remove(png);
  CliResult r = runPointrast("render terrain --points 20k --radius 0.5 --method sphere-compute -o " +
                             png.string() + " --width 160 --height 90 --frames 1 -q");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(png));
  expectCleanSphereFailure("render terrain --points 20k --method sphere-compute -o " + png.string(), png,
                           "radius");
}

TEST(SpheresCli, WrongCombinationsFailCleanly) {
  fs::path png = cliTempDir() / "bad_spheres.png";
  // Particles need a sphere method; layouts must hold the set; point-only options are refused.
  expectCleanSphereFailure("render particles-block --points 1k -o " + png.string(), png, "sphere-compute");
  expectCleanSphereFailure("render particles-block --points 1k --method sphere-compute --layout xyz -o " +
                               png.string(),
                           png, "layout xyz");
  expectCleanSphereFailure("render particles-block --points 1k --method sphere-compute --layout cubes -o " +
                               png.string(),
                           png, "unknown particle layout");
  expectCleanSphereFailure("render particles-block --points 1k --method sphere-compute --order morton -o " +
                               png.string(),
                           png, "--order");
  expectCleanSphereFailure("render no-such.mmpld --method sphere-compute -o " + png.string(), png,
                           "no-such.mmpld");
}

} // namespace pointrast::test

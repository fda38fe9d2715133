// `pointrast render --method sphere-compute` as a user runs it: particle scenes and points drawn as
// spheres write a PNG and one JSON line; wrong combinations exit 1 with one line and leave no file.
#include <cstdio>
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
                          "\"width\":320", "\"median_ms\"", "\"large_chunks\"", "\"batches\":157",
                          "\"visible_batches\"", "\"build_ms\"", "\"image_hash\""})
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

TEST(SpheresCli, BillboardOptionsOfTheRasterizationPipelines) {
  // Camera billboards draw the same image as screen ones (same hash); conservative rasterization is drawn
  // where the device has it and refused with one line elsewhere; sphere-compute and the point methods
  // refuse both options.
  fs::path png = cliTempDir() / "billboards.png";
  const std::string base = "render particles-drops --points 5k --method sphere-strip --width 160 --height 90 "
                           "--frames 1 --json -q -o " +
                           png.string();
  auto hashOf = [](const std::string& out) {
    size_t at = out.find("\"image_hash\":\"");
    return at == std::string::npos ? std::string() : out.substr(at + 14, 16);
  };
  CliResult screen = runPointrast(base);
  ASSERT_EQ(screen.exitCode, 0) << screen.err;
  EXPECT_NE(screen.out.find("\"billboard\":\"screen\""), std::string::npos) << screen.out;
  CliResult camera = runPointrast(base + " --billboard camera");
  ASSERT_EQ(camera.exitCode, 0) << camera.err;
  EXPECT_NE(camera.out.find("\"billboard\":\"camera\""), std::string::npos) << camera.out;
  EXPECT_FALSE(hashOf(screen.out).empty());
  EXPECT_EQ(hashOf(camera.out), hashOf(screen.out));
  fs::remove(png);
  CliResult conservative = runPointrast(base + " --conservative");
  if (conservative.exitCode == 0) {
    EXPECT_EQ(hashOf(conservative.out), hashOf(screen.out));
  } else {
    std::printf("skipped: %s", conservative.err.c_str());
    EXPECT_EQ(conservative.exitCode, 1);
    EXPECT_NE(conservative.err.find("conservative rasterization"), std::string::npos) << conservative.err;
    EXPECT_FALSE(fs::exists(png));
  }
  expectCleanSphereFailure(
      "render particles-drops --points 1k --method sphere-compute --billboard camera -o " + png.string(), png,
      "sphere-compute");
  expectCleanSphereFailure("render particles-drops --points 1k --method sphere-compute --conservative -o " +
                               png.string(),
                           png, "--conservative apply to");
  expectCleanSphereFailure("render particles-drops --points 1k --method sphere-strip --billboard round -o " +
                               png.string(),
                           png, "unknown billboard 'round'");
  expectCleanSphereFailure("render terrain --points 1k --billboard camera -o " + png.string(), png,
                           "--billboard and --conservative apply to the sphere methods");
  CliResult help = runPointrast("render --help");
  EXPECT_NE(help.out.find("--billboard"), std::string::npos);
  EXPECT_NE(help.out.find("--conservative"), std::string::npos);
  EXPECT_NE(help.out.find("sphere-strip"), std::string::npos) << "the sphere methods are listed";
}

} // namespace pointrast::test

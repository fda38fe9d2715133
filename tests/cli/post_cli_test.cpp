// Coloring and the resolve stage through the binary (validation layer on): every --color mode on a real
// LAS file, point size, dilation and eye-dome lighting with their pass times in --json, and one-line
// errors for what cannot be done.
#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"

namespace {

namespace fs = std::filesystem;
using Result = pointrast::test::CliResult;

Result run(const std::string& args) {
  return pointrast::test::runPointrast(args);
}

std::string data(const std::string& name) {
  return (pointrast::test::dataDir() / name).string();
}

int errorLines(const std::string& err) {
  int lines = 0;
  std::istringstream in(err);
  std::string line;
  while (std::getline(in, line))
    lines += line.rfind("pointrast:", 0) == 0;
  return lines;
}

TEST(PostCli, EveryColorModeDrawsAutzenDifferently) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  fs::path dir = pointrast::test::cliTempDir();
  std::set<std::string> hashes;
  for (std::string mode : {"rgb", "intensity", "classification", "elevation", "return", "source"}) {
    fs::path png = dir / ("color-" + mode + ".png");
    Result r = run("render " + data("las/autzen_trim.las") + " --color " + mode +
                   " --width 160 --height 100 --frames 1 --json -q -o " + png.string());
    ASSERT_EQ(r.exitCode, 0) << mode << ": " << r.err;
    nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["color"], mode);
    EXPECT_FALSE(j.contains("post")) << "no resolve stage asked for";
    hashes.insert(j["image_hash"].get<std::string>());
    EXPECT_TRUE(fs::exists(png));
  }
  EXPECT_EQ(hashes.size(), 6u);
  Result ranged =
      run("render " + data("las/autzen_trim.las") +
          " --color elevation --color-range 400,450 --width 160 --height 100 --frames 1 --json -q -o " +
          (dir / "ranged.png").string());
  ASSERT_EQ(ranged.exitCode, 0) << ranged.err;
  EXPECT_FALSE(hashes.count(nlohmann::json::parse(ranged.out)["image_hash"].get<std::string>()));
}

TEST(PostCli, ResolveStageReportsItsPasses) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  fs::path png = pointrast::test::cliTempDir() / "post.png";
  for (std::string method : {"atomicmin", "batch-prefetch", "hqs1r"}) {
    Result r = run("render " + data("las/autzen_trim.las") + " --method " + method +
                   " --point-size 3 --point-shape disc --dilate 1 --edl --width 160 --height 100 --frames 2 "
                   "--json -q -o " +
                   png.string());
    ASSERT_EQ(r.exitCode, 0) << method << ": " << r.err;
    nlohmann::json post = nlohmann::json::parse(r.out)["post"];
    EXPECT_EQ(post["point_size"], 3.0);
    EXPECT_EQ(post["point_shape"], "disc");
    EXPECT_EQ(post["dilate"], 1);
    EXPECT_EQ(post["edl_strength"], 1.0);
    for (const char* pass : {"splat_ms", "dilate_ms", "compose_ms"})
      EXPECT_GT(post[pass].get<double>(), 0.0) << method << " " << pass;
  }
  Result attenuated = run("render terrain --points 20k --point-size 2 --point-size-mode attenuated "
                          "--point-size-max 6 --edl-strength 0.5 --width 160 --height 100 --frames 1 -q -o " +
                          png.string());
  EXPECT_EQ(attenuated.exitCode, 0) << attenuated.err;
  Result text =
      run("render terrain --points 20k --dilate 2 --width 160 --height 100 --frames 1 -o " + png.string());
  EXPECT_NE(text.out.find("resolve stage"), std::string::npos) << text.out;
}

TEST(PostCli, WhatCannotBeDoneIsOneLine) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  fs::path png = pointrast::test::cliTempDir() / "refused.png";
  const std::string autzen = data("las/autzen_trim.las");
  const std::string ply = data("ply/simple_binary.ply");
  const std::pair<std::string, std::string> cases[] = {
      {autzen + " --point-size 0", "out of range"},
      {autzen + " --point-size 40", "out of range"},
      {autzen + " --point-size-mode adaptive", "LOD"},
      {autzen + " --point-shape star", "square or disc"},
      {autzen + " --dilate 9", "out of range"},
      {autzen + " --edl-radius 0", "radius"},
      {autzen + " --method hw-points --edl", "hw-points"},
      {autzen + " --color height", "classification"},
      {autzen + " --color classification --color-range 1,2", "--color-range"},
      {autzen + " --color elevation --color-range 5,1", "lo < hi"},
      {ply + " --color classification", "simple_binary.ply"},
      {"particles-drops --points 1000 --method sphere-compute --edl", "point methods"},
  };
  for (const auto& [args, words] : cases) {
    Result r = run("render " + args + " --width 64 --height 64 --frames 1 -q -o " + png.string());
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_EQ(errorLines(r.err), 1) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(words), std::string::npos) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(png)) << args;
  }
  Result help = run("render --help");
  for (const char* option : {"--color", "--point-size", "--point-size-mode", "--dilate", "--edl-strength"})
    EXPECT_NE(help.out.find(option), std::string::npos) << option;
}

} // namespace

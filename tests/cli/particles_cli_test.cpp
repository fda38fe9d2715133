// Particle files and scenes through the pointrast binary: `info` on MMPLD, `generate` of particle scenes,
// and the one-line errors of both.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;

const fs::path kData = pointrast::test::dataDir();

fs::path temp(const std::string& name) {
  return pointrast::test::cliTempDir() / name;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Exit 1, one "pointrast:" line on stderr holding `phrase`, and no output file (nor its .partial).
void expectCleanFailure(const std::string& args, const std::string& phrase, const fs::path& output = {}) {
  if (!output.empty()) fs::remove(output);
  const CliResult r = runPointrast(args);
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("pointrast: ", 0), 0u) << args << "\n" << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << args << "\n" << r.err;
  EXPECT_TRUE(contains(r.err, phrase)) << args << "\n" << r.err;
  if (!output.empty()) {
    EXPECT_FALSE(fs::exists(output)) << args;
    EXPECT_FALSE(fs::exists(output.string() + ".partial")) << args;
  }
}

TEST(ParticlesCli, HelpTeachesTheParticleScenesAndMmpld) {
  const CliResult generate = runPointrast("generate --help");
  EXPECT_EQ(generate.exitCode, 0);
  for (const char* part : {"particles-block", "particles-drops", "particles-laser", "particles-uniform",
                           "--per-particle-radius", "--mmpld", "Examples:", ".mmpld"})
    EXPECT_TRUE(contains(generate.out, part)) << part << "\n" << generate.out;
  const CliResult info = runPointrast("info --help");
  EXPECT_EQ(info.exitCode, 0);
  EXPECT_TRUE(contains(info.out, "MMPLD")) << info.out;
  EXPECT_TRUE(contains(info.out, "--frame")) << info.out;
}

TEST(ParticlesCli, InfoDescribesMmpld) {
  POINTRAST_REQUIRE_DATA("mmpld/test_xyz_double_int_double.mmpld");
  const std::string file = (kData / "mmpld/test_xyz_double_int_double.mmpld").string();
  const CliResult text = runPointrast("info " + file);
  ASSERT_EQ(text.exitCode, 0) << text.err;
  for (const char* part : {"format:  MMPLD 1.2 (102), 1 frame", "frame:   0, 4 lists, timestamp 1.23",
                           "list 0:  DOUBLE_XYZ + DOUBLE_I, 4 particles, radius 0.1, intensity 0 .. 255",
                           "list 3:  FLOAT_XYZ + NONE, 5 particles, radius 0.1, color 0,0,255,255",
                           "particles: 19\n", "radius:  0.1 .. 0.1"})
    EXPECT_TRUE(contains(text.out, part)) << part << "\n" << text.out;

  const CliResult json =
      runPointrast("info " + (kData / "mmpld/test_xyzr_float_rgba_byte.mmpld").string() + " --json");
  ASSERT_EQ(json.exitCode, 0) << json.err;
  EXPECT_EQ(json.out.find('\n'), json.out.size() - 1) << json.out; // one JSON object, one line
  for (const char* part : {"\"format\":\"MMPLD\"", "\"version\":\"1.2\"", "\"frames\":1", "\"particles\":4",
                           "\"vertex\":\"FLOAT_XYZR\"", "\"color\":\"UINT8_RGBA\"", "\"radius_min\":0.2",
                           "\"radius_max\":0.5", "\"dropped\":0"})
    EXPECT_TRUE(contains(json.out, part)) << part << "\n" << json.out;

  expectCleanFailure("info " + file + " --frame 5", "there is no frame 5");
}

TEST(ParticlesCli, GenerateWritesMmpldThatInfoReads) {
  const fs::path out = temp("laser.mmpld");
  fs::remove(out);
  const CliResult r = runPointrast("generate particles-laser --points 20k --seed 4 -o " + out.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "20.0 k particles")) << r.out;
  const CliResult info = runPointrast("info " + out.string() + " --json");
  ASSERT_EQ(info.exitCode, 0) << info.err;
  for (const char* part : {"\"version\":\"1.3\"", "\"particles\":20000", "\"vertex\":\"FLOAT_XYZ\"",
                           "\"color\":\"UINT8_RGBA\"", "\"global_radius\":0.5", "\"radius_min\":0.5"})
    EXPECT_TRUE(contains(info.out, part)) << part << "\n" << info.out;

  // The same seed gives the same file.
  const fs::path again = temp("laser2.mmpld");
  ASSERT_EQ(runPointrast("generate particles-laser --points 20k --seed 4 -q -o " + again.string()).exitCode,
            0);
  EXPECT_EQ(pointrast::test::slurp(out), pointrast::test::slurp(again));

  const fs::path per = temp("drops.mmpld");
  const CliResult r2 =
      runPointrast("generate particles-drops --points 5000 --radius 0.3 --per-particle-radius "
                   "--mmpld 1.0 -q -o " +
                   per.string());
  ASSERT_EQ(r2.exitCode, 0) << r2.err;
  EXPECT_TRUE(r2.out.empty()) << r2.out; // -q
  const CliResult info2 = runPointrast("info " + per.string());
  ASSERT_EQ(info2.exitCode, 0) << info2.err;
  EXPECT_TRUE(contains(info2.out, "MMPLD 1.0 (100)")) << info2.out;
  EXPECT_TRUE(contains(info2.out, "list 0:  FLOAT_XYZR + UINT8_RGBA, 5000 particles")) << info2.out;
}

TEST(ParticlesCli, GenerateRefusesMismatchedOptions) {
  const fs::path las = temp("x.las"), mmpld = temp("x.mmpld");
  expectCleanFailure("generate particles-block --points 1000 -o " + las.string(), "written as MMPLD", las);
  expectCleanFailure("generate terrain --points 1000 --radius 2 -o " + las.string(),
                     "--radius applies to particle", las);
  expectCleanFailure("generate tls --points 1000 --per-particle-radius -o " + las.string(),
                     "--per-particle-radius applies to particle", las);
  expectCleanFailure("generate particles-uniform --points 1000 --order morton -o " + mmpld.string(),
                     "--order applies to point scenes", mmpld);
  expectCleanFailure("generate particles-uniform --points 1000 --mmpld 1.2 -o " + mmpld.string(),
                     "--mmpld expects 1.0 or 1.3", mmpld);
  expectCleanFailure("generate particles-uniform --points 1000 --radius -1 -o " + mmpld.string(),
                     "radius must be a positive number", mmpld);
  expectCleanFailure("generate particles-foam -o " + mmpld.string(), "particles-laser", mmpld);
}

TEST(ParticlesCli, BadMmpldFilesFailCleanly) {
  POINTRAST_REQUIRE_DATA("mmpld/test_xyz_double_none.mmpld");
  const std::string bytes = pointrast::test::slurp(kData / "mmpld/test_xyz_double_none.mmpld");
  const fs::path cut = temp("cut.mmpld");
  { std::ofstream(cut, std::ios::binary) << bytes.substr(0, 200); }
  expectCleanFailure("info " + cut.string(), "truncated");
  const fs::path old = temp("future.mmpld");
  {
    std::string future = bytes;
    future[6] = char(110); // version 110
    std::ofstream(old, std::ios::binary) << future;
  }
  expectCleanFailure("info " + old.string(), "not supported");
  // The point commands say what the file is rather than failing on its content.
  expectCleanFailure("convert " + (kData / "mmpld/test_xyz_double_none.mmpld").string() + " " +
                         temp("y.las").string(),
                     "particles", temp("y.las"));
}

} // namespace

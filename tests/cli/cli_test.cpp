// The pointrast binary as a user meets it: exit codes, one-line errors, no partial output files.
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <gtest/gtest.h>

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

const fs::path kData = pointrast::test::dataDir();

int lineCount(const std::string& text) {
  int lines = 0;
  for (char c : text)
    lines += c == '\n';
  return lines;
}

// The error contract: exit 1, exactly one line on stderr (after the device line for render), no output.
void expectCleanFailure(const std::string& args, const fs::path& output = {}) {
  if (!output.empty()) fs::remove(output);
  Result r = run(args);
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  std::string errors;
  int errorLines = 0;
  size_t at = 0;
  while (at < r.err.size()) {
    size_t nl = r.err.find('\n', at);
    std::string line = r.err.substr(at, nl - at);
    if (line.rfind("pointrast:", 0) == 0) ++errorLines;
    at = nl == std::string::npos ? r.err.size() : nl + 1;
  }
  EXPECT_EQ(errorLines, 1) << args << "\n" << r.err;
  if (!output.empty()) {
    EXPECT_FALSE(fs::exists(output)) << args;
    EXPECT_FALSE(fs::exists(output.string() + ".partial")) << args;
  }
}

fs::path writeFile(const std::string& name, const std::string& bytes) {
  fs::path p = tempDir() / name;
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

} // namespace

TEST(Cli, HelpExitsZeroAndTeaches) {
  for (std::string cmd : {"--help", "render --help", "info --help", "convert --help", "generate --help"}) {
    Result r = run(cmd);
    EXPECT_EQ(r.exitCode, 0) << cmd;
    EXPECT_NE(r.out.find("Example"), std::string::npos) << cmd;
  }
}

TEST(Cli, UsageErrorsExitOne) {
  expectCleanFailure("");
  expectCleanFailure("frobnicate");
  expectCleanFailure("render --width abc -o x.png");
  expectCleanFailure("render --eye 1,2 -o " + (tempDir() / "x.png").string(), tempDir() / "x.png");
  expectCleanFailure("render --order zigzag -o " + (tempDir() / "x.png").string(), tempDir() / "x.png");
  expectCleanFailure("render --method nope -o " + (tempDir() / "x.png").string(), tempDir() / "x.png");
  expectCleanFailure("render --eye 0,0,0 --target 0,0,0 -o " + (tempDir() / "x.png").string(),
                     tempDir() / "x.png");
  expectCleanFailure("render does-not-exist.las -o " + (tempDir() / "x.png").string(), tempDir() / "x.png");
}

TEST(Cli, BadFilesFailCleanlyForInfoAndRender) {
  POINTRAST_REQUIRE_DATA("las/permutations/1.2-no-points.las");
  std::mt19937 rng(5);
  std::string random(4096, '\0');
  for (char& c : random)
    c = char(rng());
  std::string plyLie = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty float x\n"
                       "property float y\nproperty float z\nend_header\n" +
                       std::string(120, '\0');
  std::vector<fs::path> files = {kData / "las/permutations/1.2-no-points.las",
                                 kData / "laz/simple-laszip-compressor-version-1.2r0.laz",
                                 writeFile("empty.las", ""),
                                 writeFile("random.bin", random),
                                 writeFile("random.las", random),
                                 writeFile("lie.ply", plyLie)};
  fs::path png = tempDir() / "bad.png";
  for (const fs::path& f : files) {
    ASSERT_TRUE(fs::exists(f)) << f;
    expectCleanFailure("info " + f.string());
    expectCleanFailure("render " + f.string() + " -o " + png.string(), png);
  }
}

TEST(Cli, RenderAutzenWritesPngAndJson) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  fs::path png = tempDir() / "autzen.png";
  fs::remove(png);
  Result r = run("render " + (kData / "las/autzen_trim.las").string() + " -o " + png.string() +
                 " --width 400 --height 300 --frames 2 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  ASSERT_TRUE(fs::exists(png));
  std::string head = slurp(png).substr(0, 8);
  EXPECT_EQ(head, std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(lineCount(r.out), 1) << r.out;
  for (const char* key : {"\"device\"", "\"method\":\"atomicmin\"", "\"points\":110000", "\"width\":400",
                          "\"height\":300", "\"median_ms\"", "\"output\""})
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " missing in " << r.out;
}

TEST(Cli, InfoDescribesLas) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  Result r = run("info " + (kData / "las/autzen_trim.las").string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("\"points\":110000"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"color_bits\":8"), std::string::npos) << r.out;
}

TEST(Cli, GenerateConvertAndRenderRoundTrip) {
  fs::path las = tempDir() / "gen.las", morton = tempDir() / "gen_morton.las";
  fs::path a = tempDir() / "a.png", b = tempDir() / "b.png";
  ASSERT_EQ(run("generate tls --points 50k --seed 3 -o " + las.string()).exitCode, 0);
  ASSERT_EQ(
      run("convert " + las.string() + " " + morton.string() + " --order shuffled-morton --seed 9").exitCode,
      0);
  // The same points in another order render the same image (order-independent minimum).
  Result ra = run("render " + las.string() + " -o " + a.string() + " --width 320 --height 200 --json");
  Result rb = run("render " + morton.string() + " -o " + b.string() + " --width 320 --height 200 --json");
  ASSERT_EQ(ra.exitCode, 0) << ra.err;
  ASSERT_EQ(rb.exitCode, 0) << rb.err;
  auto hash = [](const std::string& json) { return json.substr(json.find("\"image_hash\""), 32); };
  EXPECT_EQ(hash(ra.out), hash(rb.out));
}

TEST(Cli, PartsGiveTheSameImage) {
  fs::path a = tempDir() / "p1.png", b = tempDir() / "p5.png";
  Result ra = run("render terrain --points 200k -o " + a.string() + " --width 320 --height 200 --json");
  Result rb =
      run("render terrain --points 200k -o " + b.string() + " --width 320 --height 200 --json --parts 5");
  ASSERT_EQ(ra.exitCode, 0) << ra.err;
  ASSERT_EQ(rb.exitCode, 0) << rb.err;
  EXPECT_EQ(slurp(a), slurp(b));
}

TEST(Cli, WritingToAMissingDirectoryLeavesNothing) {
  expectCleanFailure("render terrain --points 1000 -o /nonexistent-dir/x.png");
}

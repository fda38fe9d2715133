// The CLI given what a hostile or unlucky user gives it besides bad file contents: named pipes, names
// with control characters, symbolic link loops, names too long, a stdout that cannot be written, and a
// file whose header states more points than the device can hold. Each is one line on stderr and exit 1,
// at once.
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/stat.h>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliOptions;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;

// Long enough for lavapipe to start; a command that waits on its input is stopped and fails.
constexpr int kTimeout = 60;

std::string shellQuoted(const std::string& s) {
  std::string q = "'";
  for (char c : s)
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The lines of stderr that are ours (the device and its note come first for render).
std::vector<std::string> errorLines(const std::string& err) {
  std::vector<std::string> lines;
  size_t at = 0;
  while (at < err.size()) {
    size_t nl = err.find('\n', at);
    std::string line = err.substr(at, nl == std::string::npos ? std::string::npos : nl - at);
    if (line.rfind("device: ", 0) != 0 && line.rfind("note: ", 0) != 0) lines.push_back(line);
    at = nl == std::string::npos ? err.size() : nl + 1;
  }
  return lines;
}

// Exit 1 and exactly one line on stderr, "pointrast: " + a text that contains `expected`.
void expectOneLine(const CliResult& r, const std::string& what, const std::string& expected) {
  EXPECT_FALSE(r.signaled) << what;
  EXPECT_EQ(r.exitCode, 1) << what << "\n" << r.err;
  std::vector<std::string> lines = errorLines(r.err);
  ASSERT_EQ(lines.size(), 1u) << what << "\n" << r.err;
  EXPECT_EQ(lines[0].rfind("pointrast: ", 0), 0u) << what << "\n" << r.err;
  EXPECT_NE(lines[0].find(expected), std::string::npos) << what << "\n" << r.err;
}

fs::path freshDir(const std::string& name) {
  fs::path dir = pointrast::test::cliTempDir() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

} // namespace

TEST(CliHostilePaths, NamedPipeIsRefusedAtOnce) {
  fs::path dir = freshDir("pipe");
  fs::path pipe = dir / "cloud.las";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  const std::string p = pipe.string();
  CliOptions bounded{kTimeout, ""};
  for (std::string args : {"info " + p, "info " + p + " --json", "render " + p + " -o " + p + ".png",
                           "render " + p + " --method sphere-compute --radius 1 -o " + p + ".png",
                           "convert " + p + " " + p + ".out.las"}) {
    expectOneLine(runPointrast(args, bounded), args, "cloud.las: is a named pipe (FIFO), not a regular file");
  }
  EXPECT_FALSE(fs::exists(p + ".png"));
  EXPECT_FALSE(fs::exists(p + ".out.las"));
}

TEST(CliHostilePaths, ControlCharactersInNamesStayOnOneLine) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  fs::path dir = freshDir("names");
  const std::string name = (dir / "two\nlines\t\x1b[31m.las").string();
  std::ofstream(name) << "not a point cloud";
  const std::string shown = "two\\nlines\\t\\x1b[31m.las";
  const std::string png = (dir / "x.png").string(), las = (dir / "x.las").string();
  const std::string q = shellQuoted(name);
  for (std::string args : {"info " + q, "render -o " + png + " " + q, "convert --quiet " + q + " " + las})
    expectOneLine(runPointrast(args), args, shown);
  const std::string missing = (dir / "no\nsuch.las").string();
  expectOneLine(runPointrast("info " + shellQuoted(missing)), "info missing", "no\\nsuch.las: no such file");

  // A readable file under such a name: info's "file:" line is one line too.
  const std::string good = (dir / "a\nb.las").string();
  fs::copy_file(pointrast::test::dataDir() / "las/1.2-with-color.las", good);
  CliResult r = runPointrast("info " + shellQuoted(good));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("file:    " + dir.string() + "/a\\nb.las\nformat:"), std::string::npos) << r.out;
}

TEST(CliHostilePaths, LinkLoopsAndLongNamesAreNamedInOneLine) {
  fs::path dir = freshDir("links");
  fs::create_symlink("loop.las", dir / "loop.las");
  const std::string loop = (dir / "loop.las").string();
  const std::string tooLong = (dir / (std::string(300, 'n') + ".las")).string();
  for (const auto& [path, reason] : {std::pair{loop, std::string("Too many levels of symbolic links")},
                                     std::pair{tooLong, std::string("File name too long")}}) {
    for (std::string args :
         {"info " + path, "render " + path + " -o " + (dir / "x.png").string(),
          "render " + path + " --method sphere-compute --radius 1 -o " + (dir / "x.png").string(),
          "convert " + path + " " + (dir / "x.las").string()}) {
      CliResult r = runPointrast(args);
      expectOneLine(r, args, path + ": cannot open: " + reason);
      EXPECT_EQ(r.err.find("filesystem error"), std::string::npos) << r.err;
    }
  }
  EXPECT_FALSE(fs::exists(dir / "x.png"));
  EXPECT_FALSE(fs::exists(dir / "x.las"));
}

TEST(CliHostilePaths, UnwritableStdoutIsAnError) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this system";
  const std::string las = (pointrast::test::dataDir() / "las/1.2-with-color.las").string();
  CliOptions full{kTimeout, "/dev/full"};
  for (std::string args : {"info " + las, "info " + las + " --json", std::string("--help"),
                           std::string("info --help"), std::string("info --devices")})
    expectOneLine(runPointrast(args, full), args, "cannot write to standard output: No space left on device");
  // The same commands exit 0 with a working stdout.
  for (std::string args : {"info " + las, std::string("--help")})
    EXPECT_EQ(runPointrast(args).exitCode, 0) << args;
}

TEST(CliHostilePaths, CloudsTooLargeForTheDeviceAreRefusedBeforeReading) {
  POINTRAST_REQUIRE_DATA("las/test1_4.las");
  // A LAS 1.4 header stating 100 G points of 30 B in a sparse 3 TB file: the count passes the reader's
  // check against the file's size, no device holds the 1.6 TB the points need, and reading them would
  // take hours. The refusal must come from the header, at once.
  fs::path dir = freshDir("huge");
  std::ifstream in(pointrast::test::dataDir() / "las/test1_4.las", std::ios::binary);
  std::vector<char> header((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(header.size(), 375u);
  uint32_t pointOffset = 0;
  std::memcpy(&pointOffset, header.data() + 96, 4);
  header.resize(pointOffset);
  const uint32_t legacy = 0;
  const uint64_t points = 100'000'000'000ull;
  std::memcpy(header.data() + 107, &legacy, 4);
  std::memcpy(header.data() + 247, &points, 8);
  const fs::path huge = dir / "huge.las";
  std::ofstream(huge, std::ios::binary).write(header.data(), std::streamsize(header.size()));
  std::error_code ec;
  fs::resize_file(huge, pointOffset + points * 30, ec);
  if (ec) GTEST_SKIP() << "the temp file system holds no 3 TB sparse file: " << ec.message();

  const std::string png = (dir / "huge.png").string();
  CliOptions bounded{kTimeout, ""};
  for (std::string method : {"atomicmin", "batch"}) {
    auto start = std::chrono::steady_clock::now();
    CliResult r = runPointrast("render " + huge.string() + " -o " + png + " --method " + method, bounded);
    expectOneLine(r, method, "huge.las: 100000000000 points need 1525878 MiB of GPU memory");
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30)) << method;
  }
  expectOneLine(
      runPointrast("render " + huge.string() + " -o " + png + " --method sphere-compute --radius 1", bounded),
      "sphere-compute", "huge.las: 100000000000 particles need");
  // Generated scenes are sized before they are generated.
  expectOneLine(runPointrast("render terrain --points 1e15 -o " + png, bounded), "terrain",
                "terrain: 1000000000000000 points need");
  EXPECT_FALSE(fs::exists(png));
  fs::remove(huge); // sparse, but 3 TB to any tool that walks the temp folder later
}

// `render`'s output and blame: the image is written only once the frame is trustworthy and its result
// printable, empty clouds draw the background, and each failure names what is wrong (the data, or the
// option the user gave), not a camera option nobody gave.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using pointrast::test::slurp;

fs::path temp(const std::string& name) {
  return pointrast::test::cliTempDir() / name;
}

fs::path writeFile(const std::string& name, const std::string& bytes) {
  const fs::path p = temp(name);
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

int errorLines(const std::string& err) {
  int lines = 0;
  for (size_t at = 0; at < err.size();) {
    const size_t nl = err.find('\n', at);
    lines += err.compare(at, 10, "pointrast:") == 0;
    at = nl == std::string::npos ? err.size() : nl + 1;
  }
  return lines;
}

// image_hash of a width x height image of one RGBA8 color (the FNV-1a of app/cli_util.h).
std::string uniformImageHash(uint32_t rgba, uint32_t pixels) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (uint32_t i = 0; i < pixels; ++i)
    for (int b = 0; b < 4; ++b)
      h = (h ^ ((rgba >> (8 * b)) & 0xFF)) * 0x100000001b3ull;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

} // namespace

TEST(RenderCli, AValidationErrorLeavesNoImage) {
  const fs::path png = temp("validation.png");
  fs::remove(png);
  setenv("POINTRAST_INJECT_VALIDATION_ERROR", "1", 1);
  CliResult r = runPointrast("render --points 10k --width 64 --height 48 -q -o " + png.string());
  unsetenv("POINTRAST_INJECT_VALIDATION_ERROR");
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(errorLines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("validation layer reported 1 error"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(png)) << "exit 1 must leave no image";
}

TEST(RenderCli, JsonOfAPathThatIsNotUtf8IsPrinted) {
  const fs::path input = writeFile("cloud-\xff.xyz", "1 2 3\n4 5 6\n7 8 10\n");
  const fs::path png = temp("not-utf8.png");
  fs::remove(png);
  CliResult r = runPointrast("render '" + input.string() +
                             "' --width 64 --height 48 --frames 1 -q --json -o " + png.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(png));
  nlohmann::json j = nlohmann::json::parse(r.out); // valid UTF-8, the odd byte replaced
  EXPECT_EQ(j["points"], 3);
  EXPECT_NE(j["input"].get<std::string>().find("cloud-"), std::string::npos);
}

TEST(RenderCli, EmptyCloudsDrawTheBackground) {
  POINTRAST_REQUIRE_DATA("las/no-points.las");
  const std::vector<fs::path> empty = {
      pointrast::test::dataDir() / "las/no-points.las",
      writeFile("none.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
                            "property float z\nend_header\n"),
      writeFile("nan.xyz", "nan nan nan\n1 inf 2\n")};
  for (const fs::path& input : empty) {
    for (const char* method : {"atomicmin", "batch", "hw-points"}) {
      SCOPED_TRACE(input.string() + " / " + method);
      const fs::path png = temp("empty.png");
      fs::remove(png);
      CliResult r = runPointrast("render " + input.string() + " --method " + method +
                                 " --background 10,20,30 --width 64 --height 48 --frames 1 -q --json -o " +
                                 png.string());
      ASSERT_EQ(r.exitCode, 0) << r.err;
      EXPECT_TRUE(fs::exists(png));
      nlohmann::json j = nlohmann::json::parse(r.out);
      EXPECT_EQ(j["points"], 0);
      EXPECT_EQ(j["image_hash"], uniformImageHash(0xFF1E140Au, 64 * 48)) << "only the background";
    }
  }
}

TEST(RenderCli, CoordinatesBeyondRangeNameTheData) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  std::string las = slurp(pointrast::test::dataDir() / "las/1.2-with-color.las");
  ASSERT_GT(las.size(), 227u);
  for (int axis = 0; axis < 3; ++axis) { // the header's x, y, z offsets (LAS 1.2, bytes 155..178)
    const double offset = 1e20;
    std::memcpy(las.data() + 155 + 8 * axis, &offset, 8);
  }
  const std::vector<fs::path> inputs = {writeFile("far-offset.las", las),
                                        writeFile("far.xyz", "1e300 0 0\n-1e300 1 1\n")};
  for (const fs::path& input : inputs) {
    const fs::path png = temp("far.png");
    fs::remove(png);
    CliResult r = runPointrast("render " + input.string() + " --width 64 --height 48 -q -o " + png.string());
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_EQ(errorLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(input.filename().string() + ": coordinates reach"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("--"), std::string::npos) << "no option was given wrong: " << r.err;
    EXPECT_FALSE(fs::exists(png));
  }
}

TEST(RenderCli, CameraOptionsAreNamedWhenTheyAreWrong) {
  struct Case {
    const char* args;
    const char* message;
  };
  for (const Case& c : {Case{"--fov 0", "--fov must be between 0 and 180 degrees"},
                        Case{"--fov 180 --eye 1,1,1", "--fov must be between 0 and 180 degrees"},
                        Case{"--eye 0,0,1 --target 0,0,0", "--up is parallel to the view direction"},
                        Case{"--eye 0,0,1 --up 0,0,0", "--up must not be zero"},
                        Case{"--eye 1,2,3 --target 1,2,3", "--eye and --target must differ"},
                        Case{"--near -1", "--near must be"}}) {
    const fs::path png = temp("camera.png");
    fs::remove(png);
    CliResult r = runPointrast(std::string("render --points 1000 --width 32 --height 32 -q ") + c.args +
                               " -o " + png.string());
    EXPECT_EQ(r.exitCode, 1) << c.args << "\n" << r.err;
    EXPECT_EQ(errorLines(r.err), 1) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(png)) << c.args;
  }
}

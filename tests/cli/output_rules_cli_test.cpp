// Outputs that cannot be written are refused before any work, with one line naming the reason: a folder
// that refuses new files, a file where a folder should be; and `lod` refuses inputs whose coordinates the
// renderer could not draw, naming a damaged scale when that is the cause.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::cliTempDir;
using pointrast::test::runPointrast;

fs::path fresh(const std::string& name) {
  const fs::path dir = cliTempDir() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

size_t lines(const std::string& text) {
  return size_t(std::count(text.begin(), text.end(), '\n'));
}

// Commands that write `target`, given an input they would have to read first.
std::vector<std::string> writers(const std::string& input, const fs::path& folder) {
  const std::string f = folder.string();
  return {"lod " + input + " -o " + f + "/octree -q",
          "convert " + input + " " + f + "/out.las -q",
          "render " + input + " -o " + f + "/out.png --width 64 --height 48",
          "render " + input + " --path orbit --video " + f + "/fly.mp4 --width 64 --height 48"};
}

// The input is not a point file: a command that read it before checking its output would complain about
// the input instead, so the message proves the order.
fs::path unreadableInput(const fs::path& dir) {
  const fs::path input = dir / "not_points.las";
  std::ofstream(input) << "this is not a LAS file\n";
  return input;
}

TEST(OutputRulesCli, AFolderThatRefusesFilesIsRefusedBeforeTheWork) {
  const fs::path dir = fresh("output_readonly");
  const std::string input = unreadableInput(dir).string();
  // sysfs takes no new files, from root either: the probe the commands make fails there whoever runs.
  std::vector<fs::path> folders = {"/sys"};
  const fs::path locked = dir / "locked";
  fs::create_directories(locked);
  chmod(locked.c_str(), 0555);
  if (geteuid() != 0) folders.push_back(locked); // root writes into a 0555 folder: nothing to refuse
  for (const fs::path& folder : folders)
    for (const std::string& args : writers(input, folder)) {
      const auto r = runPointrast(args);
      EXPECT_FALSE(r.signaled) << args;
      EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
      EXPECT_EQ(lines(r.err), 1u) << args << "\n" << r.err;
      EXPECT_NE(r.err.find("cannot write in the folder " + folder.string()), std::string::npos)
          << args << "\n" << r.err;
      EXPECT_EQ(r.out.find("device:"), std::string::npos) << args << ": a device was opened first";
    }
  chmod(locked.c_str(), 0755);
  EXPECT_TRUE(fs::is_empty(locked));
}

TEST(OutputRulesCli, AFileOnTheWayIsNamed) {
  const fs::path dir = fresh("output_file");
  const std::string input = unreadableInput(dir).string();
  const fs::path file = dir / "plain";
  std::ofstream(file) << "a file";
  for (const std::string& args : writers(input, file / "sub")) {
    const auto r = runPointrast(args);
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(file.string() + " is a file, not a folder"), std::string::npos) << args << "\n" << r.err;
  }
  const auto missing = runPointrast("convert " + input + " " + (dir / "none" / "out.las").string());
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("the folder " + (dir / "none").string() + " does not exist"), std::string::npos)
      << missing.err;
  const auto empty = runPointrast("lod " + input + " -o ''");
  EXPECT_EQ(empty.exitCode, 1);
  EXPECT_NE(empty.err.find("-o: give the name of a new folder"), std::string::npos) << empty.err;
}

TEST(OutputRulesCli, LodIntoANewFolderNamedWithASlash) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  const fs::path dir = fresh("output_slash");
  const auto r = runPointrast("lod " + (pointrast::test::dataDir() / "las" / "1.2-with-color.las").string() +
                              " -o " + (dir / "new").string() + "/ -q");
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "new" / "metadata.json"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

// A copy of a LAS 1.2 file with one header double replaced (scale x at byte 131, offset x at 155).
fs::path withHeaderDouble(const fs::path& dir, const std::string& name, size_t at, double value) {
  std::ifstream in(pointrast::test::dataDir() / "las" / "1.2-with-color.las", std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::memcpy(bytes.data() + at, &value, sizeof value);
  const fs::path out = dir / name;
  std::ofstream(out, std::ios::binary) << bytes;
  return out;
}

TEST(OutputRulesCli, LodRefusesCoordinatesTheRendererCannotDraw) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  const fs::path dir = fresh("output_range");
  struct Case {
    fs::path input;
    const char* says;
  };
  const std::vector<Case> cases = {
      {withHeaderDouble(dir, "offset_1e16.las", 155, 1e16), "coordinates reach 1e+16, beyond the 1e+15"},
      {withHeaderDouble(dir, "offset_-3e15.las", 155, -3e15), "beyond the 1e+15"},
      {withHeaderDouble(dir, "scale_1e300.las", 131, 1e300), "a scale of 1e+300 puts coordinates beyond"},
      {withHeaderDouble(dir, "scale_1e9.las", 131, 1e9), "a scale of 1e+09 puts coordinates beyond"},
  };
  for (const Case& c : cases) {
    const auto r = runPointrast("lod " + c.input.string() + " -o " + (dir / "octree").string() + " -q");
    EXPECT_FALSE(r.signaled) << c.input << "\n" << r.err;
    EXPECT_EQ(r.exitCode, 1) << c.input << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("octree:"), std::string::npos) << "about the output, not the input: " << r.err;
    EXPECT_FALSE(fs::exists(dir / "octree"));
  }
  // Within the limit an offset far from the origin is drawn as usual.
  const auto near = runPointrast("lod " + withHeaderDouble(dir, "offset_1e14.las", 155, 1e14).string() + " -o " +
                                 (dir / "octree").string() + " -q");
  EXPECT_EQ(near.exitCode, 0) << near.err;
}

} // namespace

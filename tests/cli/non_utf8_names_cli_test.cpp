// File names that are not UTF-8 (byte 0xFF: a Latin-1 name on a Linux disk) in everything the CLI writes as
// JSON: the name is replaced (U+FFFD) in the output, never an exception that loses a finished run's report.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "test_data.h"

namespace pointrast::test {
namespace {

namespace fs = std::filesystem;

// A fresh folder under the test's temp dir whose name ends in byte 0xFF.
fs::path nonUtf8Dir(const std::string& stem) {
  const fs::path dir = cliTempDir() / (stem + "\xff");
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// The one JSON object a command printed; fails the test when stdout is not JSON.
nlohmann::json parsed(const CliResult& r) {
  try {
    return nlohmann::json::parse(r.out);
  } catch (const nlohmann::json::exception& e) {
    ADD_FAILURE() << e.what() << "\n" << r.out;
    return {};
  }
}

const std::string kReplacement = "\xef\xbf\xbd"; // U+FFFD in UTF-8

TEST(NonUtf8Names, BenchIoWritesItsReportsWithTheCommit) {
  POINTRAST_REQUIRE_DATA("laz/simple.laz");
  const fs::path dir = nonUtf8Dir("io");
  const fs::path laz = dir / "simple\xff.laz";
  fs::copy_file(dataDir() / "laz" / "simple.laz", laz);
  CliResult r =
      runPointrast("bench-io '" + laz.string() + "' --threads 1 --repeats 1 --no-read-cloud --json" +
                   " --quiet --name io --out '" + dir.string() + "'");
  ASSERT_FALSE(r.signaled) << r.err;
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json printed = parsed(r);
  EXPECT_NE(printed["results"][0]["file"].get<std::string>().find(kReplacement), std::string::npos);
  std::ifstream file(dir / "io.json");
  const nlohmann::json written = nlohmann::json::parse(file);
  ASSERT_TRUE(written.contains("commit"));
  EXPECT_FALSE(written["commit"].get<std::string>().empty());
  EXPECT_TRUE(fs::exists(dir / "io.md"));
}

TEST(NonUtf8Names, LodPrintsItsJsonAndWritesTheOctree) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  const fs::path dir = nonUtf8Dir("lod");
  const fs::path las = dir / "thin\xff.las";
  fs::copy_file(dataDir() / "las" / "1.2-with-color.las", las);
  const fs::path out = dir / "octree\xff";
  CliResult r = runPointrast("lod '" + las.string() + "' -o '" + out.string() + "' --json -q");
  ASSERT_FALSE(r.signaled) << r.err;
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(parsed(r)["output"].get<std::string>().find(kReplacement), std::string::npos);
  std::ifstream metadata(out / "metadata.json");
  nlohmann::json written;
  EXPECT_NO_THROW(written = nlohmann::json::parse(metadata));
  EXPECT_NE(written.value("name", "").find(kReplacement), std::string::npos) << written.dump();
}

// A camera path rendered into frames (lavapipe, validation on): the summary names the folder.
TEST(NonUtf8Names, RenderPathPrintsItsJson) {
  const fs::path dir = nonUtf8Dir("path");
  const fs::path path = dir / "path.json";
  std::ofstream(path) << R"({"format": "pointrast-camera-path", "version": 1, "keyframes": [
    {"time": 0, "eye": [0, -60, 30], "target": [0, 0, 0], "up": [0, 0, 1], "fov": 60},
    {"time": 0.2, "eye": [60, 0, 30], "target": [0, 0, 0], "up": [0, 0, 1], "fov": 60}]})";
  const fs::path frames = dir / "frames\xff";
  CliResult r = runPointrast("render terrain --points 20k --path '" + path.string() + "' --frames-dir '" +
                             frames.string() + "' --fps 10 --width 64 --height 48 --json -q");
  ASSERT_FALSE(r.signaled) << r.err;
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(parsed(r)["output"].get<std::string>().find(kReplacement), std::string::npos);
}

} // namespace
} // namespace pointrast::test

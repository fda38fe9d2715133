// The profile in the page (headless chromium through tests/web/browser.mjs) against `pointrast serve`: the
// profile tool's clicks draw a line, the page shows the picture the server cut, and its LAS and CSV
// downloads. Each must equal what `pointrast profile` writes for the same line, width and size: the
// picture pixel for pixel, the LAS as the same multiset of records, the CSV byte for byte. On a LAS file
// (a cloud loaded whole) and on an octree (read node by node).
#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "image_compare.h"
#include "las_records.h"
#include "serve_harness.h"

namespace pointrast::test {
namespace {

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

class BrowserProfile : public ::testing::Test {
protected:
  void SetUp() override {
    const std::string dir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";
    if (!std::filesystem::exists(dir + "/node_modules/playwright-core"))
      FAIL() << "playwright-core is not installed: run scripts/web-test-setup.sh (npm ci in tests/web)";
    if (!std::filesystem::exists("/usr/bin/chromium"))
      FAIL() << "chromium is missing: run scripts/install-deps.sh";
  }

  // Serves `input` with `serveOptions`, clicks `pixels` with the profile tool (the page's default width),
  // and compares the page's picture and downloads with `pointrast profile`'s.
  void drawAndCompare(const std::string& input, const std::string& serveOptions, const Json& pixels,
                      const std::string& name) {
    // The server's temporary files in a folder of this test's own (tests beside it export too).
    const auto tmp = scratchDir(name + "_tmp");
    ServeProcess server("'" + input + "' " + serveOptions, "env TMPDIR='" + tmp.string() + "'");
    ASSERT_TRUE(server.listening()) << server.stderrText();
    const auto dir = scratchDir(name);
    const std::string size = "600x300";
    Json r = browser("profile", server.url(), dir,
                     {{"pixels", pixels}, {"size", size}, {"downloads", {"las", "csv"}}});
    EXPECT_EQ(r["errors"], Json::array());
    const Json& profile = r["profile"];
    ASSERT_TRUE(profile.is_object() && profile.contains("line")) << r.dump();
    // The line holds the picked points, one x,y vertex a click; the width is the page's default.
    const std::string line = profile["line"];
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 2 * std::ptrdiff_t(pixels.size()) - 1) << line;
    const std::string width = profile["width"];
    EXPECT_FALSE(r["defaultWidth"].get<std::string>().empty());
    EXPECT_EQ(width, r["defaultWidth"]);
    EXPECT_EQ(profile["size"], size);
    EXPECT_EQ(r["visible"], true);
    EXPECT_EQ(r["imageSize"], Json::array({600, 300}));
    const uint64_t points = profile["points"];
    EXPECT_GT(points, 50u) << "the test's line cuts too few points to mean much";

    const std::string ref = (dir / "ref").string();
    const std::string command = "'" + pointrastBinary() + "' profile '" + input + "' --line '" + line +
                                "' --width '" + width + "' --size " + size + " -o '" + ref + ".png' --las '" +
                                ref + ".las' --csv '" + ref + ".csv' -q 2>&1";
    const std::string printed = commandOutput(command);
    ASSERT_TRUE(std::filesystem::exists(ref + ".png")) << command << "\n" << printed;

    // The picture, pixel for pixel.
    ASSERT_TRUE(r["image"].is_string()) << r.dump();
    std::vector<uint32_t> shown, expected;
    uint32_t sw = 0, sh = 0, ew = 0, eh = 0;
    ASSERT_TRUE(readPng(r["image"].get<std::string>(), shown, sw, sh)) << "the page's picture is no PNG";
    ASSERT_TRUE(readPng(ref + ".png", expected, ew, eh));
    ASSERT_EQ(sw, ew);
    ASSERT_EQ(sh, eh);
    size_t differ = 0;
    for (size_t i = 0; i < shown.size(); ++i)
      differ += shown[i] != expected[i];
    EXPECT_EQ(differ, 0u) << "pixels that differ from profile -o, of " << shown.size();

    // The LAS download: the records `profile --las` writes, as a multiset.
    const Json& las = r["downloads"]["las"];
    ASSERT_TRUE(las.contains("file")) << r.dump();
    EXPECT_EQ(las["points"], points);
    LasRecords got = readLasRecords(las["file"].get<std::string>());
    LasRecords want = readLasRecords(ref + ".las");
    EXPECT_EQ(got.records.size(), points);
    ASSERT_EQ(got.records.size(), want.records.size());
    std::sort(got.records.begin(), got.records.end());
    std::sort(want.records.begin(), want.records.end());
    EXPECT_TRUE(got.records == want.records) << "the downloaded records are not profile --las's";
    EXPECT_EQ(got.scale, want.scale);
    EXPECT_EQ(got.offset, want.offset);

    // The CSV download, byte for byte.
    const Json& csv = r["downloads"]["csv"];
    ASSERT_TRUE(csv.contains("file")) << r.dump();
    EXPECT_EQ(csv["points"], points);
    const std::string csvBytes = fileBytes(csv["file"].get<std::string>());
    EXPECT_GT(csvBytes.size(), 100u);
    EXPECT_TRUE(csvBytes == fileBytes(ref + ".csv")) << "the downloaded CSV is not profile --csv's";

    // The server cut one picture a click from the second on, and one file a download; no temporary
    // folder is left behind.
    server.waitFor(
        [](const Json& e) { return e.value("event", "") == "profile" && e.value("output", "") == "csv"; },
        10);
    size_t cuts = 0;
    for (const Json& e : server.events())
      cuts += e.value("event", "") == "profile" ? 1 : 0;
    EXPECT_EQ(cuts, pixels.size() - 1 + 2);
    EXPECT_EQ(commandOutput("ls -d '" + tmp.string() + "'/pointrast-export-* 2>/dev/null"), "");
    EXPECT_EQ(server.stop(), 0) << server.stderrText();
    const auto exit = server.exitEvent();
    ASSERT_TRUE(exit);
    EXPECT_EQ((*exit)["validation_errors"], 0);
    std::filesystem::remove_all(dir);
  }
};

// Pixels right of the panel (its left 390 pixels) that show points of autzen_trim from kAutzenCamera.
const Json kPixels = {{405, 330}, {460, 230}};

TEST_F(BrowserProfile, TheProfileOfALoadedCloudEqualsProfileCommand) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  drawAndCompare(autzen(), kAutzenCamera, kPixels, "browser_profile_las");
}

TEST_F(BrowserProfile, TheProfileOfAnOctreeEqualsProfileCommand) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default/metadata.json");
  drawAndCompare((dataDir() / "potree/autzen_trim_default").string(),
                 std::string(kAutzenCamera) + " --min-node-px 0", kPixels, "browser_profile_octree");
}

} // namespace
} // namespace pointrast::test

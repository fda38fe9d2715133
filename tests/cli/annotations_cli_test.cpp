// `render --annotations`: markers and lines land on the pixels this test projects itself from the camera it
// passes, a line behind a wall of points is hidden, for a loaded cloud and for an octree, the overlay
// changes nothing else, and bad annotation files or combinations are refused.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::runPointrast;

constexpr int kW = 160, kH = 120;

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  std::array<int, 3> at(int x, int y) const {
    const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 4;
    return {rgba[i], rgba[i + 1], rgba[i + 2]};
  }
};

Image readPng(const fs::path& file) {
  Image image;
  int channels = 0;
  uint8_t* data = stbi_load(file.c_str(), &image.width, &image.height, &channels, 4);
  if (!data) return image;
  image.rgba.assign(data, data + size_t(image.width) * size_t(image.height) * 4);
  stbi_image_free(data);
  return image;
}

// The camera of every render here: from (0, -10, 0) along +y, z up, 60 degrees, kW x kH. The pixel of a
// point by docs/design.md: view x is world x, view y is world z, depth is y + 10.
const char* kCamera = "--eye 0,-10,0 --target 0,0,0 --up 0,0,1 --fov 60 --width 160 --height 120";
std::array<int, 2> pixelOf(double x, double y, double z) {
  const double depth = y + 10, f = 1 / std::tan(30.0 * M_PI / 180), aspect = double(kW) / kH;
  return {int(std::floor((x * f / aspect / depth + 1) / 2 * kW)),
          int(std::floor((1 - z * f / depth) / 2 * kH))};
}

// A gray wall of points in the plane y = 0 covering x in [-2, 0], z in [-3, 3] (the left half of the view
// at that depth), dense enough to leave no hole at this size.
fs::path wallCloud() {
  const fs::path file = pointrast::test::cliTempDir() / "wall.xyz";
  std::ofstream out(file);
  for (int i = 0; i <= 200; ++i)
    for (int k = 0; k <= 300; ++k)
      out << -2 + i * 0.01 << " 0 " << -3 + k * 0.02 << " 128 128 128\n";
  return file;
}

fs::path writeText(const std::string& name, const std::string& text) {
  const fs::path file = pointrast::test::cliTempDir() / name;
  std::ofstream(file) << text;
  return file;
}

// Renders `cloud` (a file, or an octree folder) with and without the annotations and checks the overlay.
void expectMarkersAndLinesOnTheProjectedPixels(const fs::path& cloud) {
  // A red point marker in the open right half at depth 12, and a green line at depth 15 (behind the wall)
  // from x = -3 to x = 3, z = -1.
  const fs::path annotations = writeText("scene.json", R"({"version": 1, "annotations": [
    {"type": "point", "color": [255, 0, 0], "points": [[2.5, 2, 1.5]]},
    {"type": "distance", "color": [0, 255, 0], "points": [[-3, 5, -1], [3, 5, -1]]}]})");
  const fs::path png = pointrast::test::cliTempDir() / "annotated.png";
  const auto r = runPointrast("render " + cloud.string() + " " + kCamera + " --frames 1 -q --annotations " +
                              annotations.string() + " -o " + png.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Image image = readPng(png);
  ASSERT_EQ(image.width, kW);
  ASSERT_EQ(image.height, kH);
  const auto marker = pixelOf(2.5, 2, 1.5);
  EXPECT_EQ(image.at(marker[0], marker[1]), (std::array<int, 3>{255, 0, 0}));
  // The line's row: green in the open right half, never green over the wall (where the gray points are).
  const auto leftEnd = pixelOf(-3, 5, -1), rightEnd = pixelOf(3, 5, -1);
  const int row = leftEnd[1], wallEdge = pixelOf(0, 0, 0)[0];
  int green = 0, gray = 0;
  for (int x = leftEnd[0] + 5; x < rightEnd[0] - 5; ++x) {
    const auto c = image.at(x, row);
    if (x < wallEdge - 1) {
      EXPECT_NE(c, (std::array<int, 3>{0, 255, 0})) << "line drawn over the wall at x " << x;
      gray += c == std::array<int, 3>{128, 128, 128};
    } else if (x > wallEdge + 1) {
      green += c == std::array<int, 3>{0, 255, 0};
    }
  }
  EXPECT_GT(gray, 10);
  EXPECT_EQ(green, rightEnd[0] - 5 - (wallEdge + 2)) << "the line is missing where nothing hides it";

  // The same render without the file: no red at the marker, so the overlay made it.
  const fs::path plain = pointrast::test::cliTempDir() / "plain.png";
  ASSERT_EQ(runPointrast("render " + cloud.string() + " " + kCamera + " --frames 1 -q -o " + plain.string())
                .exitCode,
            0);
  EXPECT_NE(readPng(plain).at(marker[0], marker[1]), (std::array<int, 3>{255, 0, 0}));
}

// An octree of `input` in a fresh folder, built with `pointrast lod`.
fs::path buildOctree(const fs::path& input, const std::string& name) {
  const fs::path octree = pointrast::test::cliTempDir() / name;
  fs::remove_all(octree);
  const auto r = runPointrast("lod " + input.string() + " -q -o " + octree.string());
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return octree;
}

TEST(AnnotationsCli, MarkersAndLinesLandOnTheProjectedPixelsAndHideBehindPoints) {
  expectMarkersAndLinesOnTheProjectedPixels(wallCloud());
}

TEST(AnnotationsCli, OnAnOctreeMarkersAndLinesLandOnTheProjectedPixelsAndHideBehindPoints) {
  const fs::path octree = buildOctree(wallCloud(), "wall_octree");
  ASSERT_FALSE(testing::Test::HasFailure());
  expectMarkersAndLinesOnTheProjectedPixels(octree);
  // lod-hqs keeps no depth per pixel without the resolve stage; the overlay draws over one mono image.
  const fs::path annotations = writeText("empty.json", R"({"version": 1, "annotations": []})");
  const fs::path png = pointrast::test::cliTempDir() / "octree_refused.png";
  for (const std::string& args : {std::string("--method lod-hqs"), std::string("--method lod --stereo")}) {
    fs::remove(png);
    const auto r = runPointrast("render " + octree.string() + " " + args + " --frames 1 -q --annotations " +
                                annotations.string() + " -o " + png.string());
    EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(args == "--method lod-hqs" ? "needs the depth of each pixel" : "not --stereo"),
              std::string::npos)
        << args << "\n"
        << r.err;
    EXPECT_FALSE(fs::exists(png)) << args;
  }
}

// On an octree of a real survey, with the default camera: the annotated image equals the plain one except
// in the small square of the one marker, which floats above the middle of the cloud (no points in front).
TEST(AnnotationsCli, OnAnOctreeTheOverlayChangesOnlyItsOwnPixels) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const fs::path octree = buildOctree(pointrast::test::dataDir() / "las/autzen_trim.las", "autzen_octree");
  ASSERT_FALSE(testing::Test::HasFailure());
  std::ifstream file(octree / "metadata.json");
  const nlohmann::json metadata = nlohmann::json::parse(file, nullptr, false);
  double lo[3] = {}, hi[3] = {};
  bool found = false;
  for (const auto& attribute : metadata.value("attributes", nlohmann::json::array()))
    if (attribute["name"] == "position") {
      for (int i = 0; i < 3; ++i) {
        lo[i] = attribute["min"][i].get<double>();
        hi[i] = attribute["max"][i].get<double>();
      }
      found = true;
    }
  ASSERT_TRUE(found) << "no position bounds in " << (octree / "metadata.json");
  const std::string marker = "[" + std::to_string((lo[0] + hi[0]) / 2) + ", " +
                             std::to_string((lo[1] + hi[1]) / 2) + ", " +
                             std::to_string(hi[2] + (hi[2] - lo[2]) / 4) + "]";
  const fs::path annotations = writeText("above.json", R"({"version": 1, "annotations": [
    {"type": "point", "color": [255, 0, 255], "points": [)" +
                                                           marker + "]}]}");
  const fs::path annotated = pointrast::test::cliTempDir() / "octree_annotated.png";
  const fs::path plain = pointrast::test::cliTempDir() / "octree_plain.png";
  const std::string common = "render " + octree.string() + " --width 160 --height 120 --frames 1 -q ";
  const auto r = runPointrast(common + "--annotations " + annotations.string() + " -o " + annotated.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  ASSERT_EQ(runPointrast(common + "-o " + plain.string()).exitCode, 0);
  const Image a = readPng(annotated), b = readPng(plain);
  ASSERT_EQ(a.width, kW);
  ASSERT_EQ(b.width, kW);
  ASSERT_EQ(a.height, b.height);
  int x0 = kW, y0 = kH, x1 = -1, y1 = -1, magenta = 0, points = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      points += b.at(x, y) != std::array<int, 3>{0, 0, 0};
      if (a.at(x, y) == b.at(x, y)) continue;
      x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
      magenta += a.at(x, y) == std::array<int, 3>{255, 0, 255};
    }
  EXPECT_GT(points, kW * kH / 10) << "the plain image shows hardly any of the cloud";
  EXPECT_EQ(magenta, 7 * 7) << "the marker's square is not whole";
  // The marker: 7 x 7 pixels of its color in a one-pixel outline, nothing changed outside that square.
  EXPECT_LE(x1 - x0, 8);
  EXPECT_LE(y1 - y0, 8);
}

TEST(AnnotationsCli, BadFilesAndCombinationsAreRefusedWithoutOutput) {
  const fs::path png = pointrast::test::cliTempDir() / "refused.png";
  const fs::path bad =
      writeText("bad.json", R"({"version": 1, "annotations": [{"type": "angle", "points": [[0,0,0]]}]})");
  const fs::path good = writeText("good.json", R"({"version": 1, "annotations": []})");
  struct Case {
    std::string args, expected;
  };
  const Case cases[] = {
      {"--annotations " + bad.string(), "annotation 1 (angle): needs exactly 3 points"},
      {"--annotations /nonexistent.json", "no such annotations file"},
      {"--annotations " + good.string() + " --method hqs", "needs the depth of each pixel"},
      {"--annotations " + good.string() + " --stereo --method batch", "not --stereo"},
      {"--annotations " + good.string() + " --method sphere-compute", "point methods"},
  };
  for (const Case& c : cases) {
    fs::remove(png);
    const auto r = runPointrast("render terrain --points 10k --width 64 --height 48 --frames 1 -q " + c.args +
                                " -o " + png.string());
    EXPECT_EQ(r.exitCode, 1) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(png)) << c.args;
  }
}

} // namespace

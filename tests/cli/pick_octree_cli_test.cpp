// render --method lod --pick X,Y --json on an octree built from a LAS file: the point the lod pass drew at
// the pixel, read from its node, is a point of the file with every attribute the file gives it, and the
// point render --pick finds on the file itself at that pixel; lod-hqs and frames drawn in passes say why
// they cannot be picked from.
#include <filesystem>
#include <map>
#include <string>
#include <tuple>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "io/reader.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;

const std::string kCamera = " --eye 636300,848700,900 --target 636600,849200,450 --up 0,0,1 --fov 60";
const std::string kSize = " --width 320 --height 240 --frames 1 --json -q";

std::string autzen() {
  return (pointrast::test::dataDir() / "las" / "autzen_trim.las").string();
}

nlohmann::json pickOf(const std::string& input, const std::string& options, int x, int y) {
  const fs::path png = pointrast::test::cliTempDir() / "pick_octree.png";
  const CliResult r = runPointrast("render '" + input + "' -o '" + png.string() + "'" + kCamera + kSize +
                                   options + " --pick " + std::to_string(x) + "," + std::to_string(y));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  if (!j.is_object() || !j.contains("pick")) {
    ADD_FAILURE() << "render printed " << r.out << r.err;
    return nlohmann::json::object();
  }
  return j["pick"];
}

class PickOctreeCli : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    octree_ = pointrast::test::cliTempDir() / "pick_autzen_octree";
    fs::remove_all(octree_);
    if (!fs::exists(autzen())) return;
    const CliResult r = runPointrast("lod '" + autzen() + "' -o '" + octree_.string() + "' -q");
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  static fs::path octree_;
};
fs::path PickOctreeCli::octree_;

TEST_F(PickOctreeCli, TheLodPassPointIsTheFilesPointWithItsAttributes) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const pointrast::PointCloud cloud = pointrast::io::readCloud(autzen());
  std::map<std::tuple<double, double, double>, uint64_t> byPosition;
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    const glm::dvec3 w = cloud.world(i);
    byPosition[{w.x, w.y, w.z}] = i;
  }
  // Pixels where the file drawn from memory shows a point; the octree's 30-bit positions may move a point
  // across a pixel border, so most, not all, of them pick the very same point.
  int checked = 0, samePoint = 0;
  const int pixels[][2] = {{160, 120}, {100, 150}, {250, 90}, {200, 200}, {60, 210}, {300, 60}, {20, 230}};
  for (const auto& [x, y] : pixels) {
    const nlohmann::json file = pickOf(autzen(), "", x, y);
    if (!file["point"].is_object()) continue;
    const nlohmann::json lod = pickOf(octree_.string(), " --method lod --min-node-px 0", x, y);
    EXPECT_EQ(lod["pixel"], nlohmann::json({x, y}));
    if (!lod["point"].is_object()) continue;
    ++checked;
    const nlohmann::json& p = lod["point"];
    EXPECT_EQ(p["node"].get<std::string>().rfind('r', 0), 0u) << p.dump();
    EXPECT_TRUE(p["index"].is_number_unsigned()) << p.dump();
    const auto found = byPosition.find({p["x"].get<double>(), p["y"].get<double>(), p["z"].get<double>()});
    ASSERT_NE(found, byPosition.end()) << "not a point of the file: " << p.dump();
    const uint64_t i = found->second;
    EXPECT_EQ(p["intensity"], cloud.intensity[i]) << p.dump();
    EXPECT_EQ(p["classification"], cloud.classification[i]) << p.dump();
    EXPECT_EQ(p["return_number"], cloud.returnNumber[i]) << p.dump();
    EXPECT_EQ(p["point_source_id"], cloud.pointSourceId[i]) << p.dump();
    const uint32_t c = cloud.colors[i];
    EXPECT_EQ(p["color"], nlohmann::json({c & 0xFF, (c >> 8) & 0xFF, (c >> 16) & 0xFF})) << p.dump();
    // The octree's pick holds the cloud's keys and more (GPS time, number of returns, ...): the cloud's
    // keys compare.
    nlohmann::json b = file["point"], a = nlohmann::json::object();
    b.erase("index");
    for (const auto& [key, value] : b.items())
      if (p.contains(key)) a[key] = p[key];
    samePoint += a == b;
  }
  EXPECT_GE(checked, 4);
  EXPECT_GE(samePoint * 5, checked * 4) << samePoint << " of " << checked;
  // Above the horizon: no point.
  EXPECT_EQ(pickOf(octree_.string(), " --method lod --min-node-px 0", 2, 2)["point"],
            pickOf(autzen(), "", 2, 2)["point"]);
}

TEST_F(PickOctreeCli, FramesWithoutAPointPerPixelSayWhy) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  // A node cache of a fifth of the octree: the frame is drawn in passes.
  const nlohmann::json passes =
      pickOf(octree_.string(), " --method lod --min-node-px 0 --gpu-memory 512k", 160, 120);
  ASSERT_TRUE(passes["point"].is_string()) << passes.dump();
  EXPECT_EQ(passes["point"].get<std::string>().rfind("unavailable: ", 0), 0u) << passes.dump();
  const fs::path png = pointrast::test::cliTempDir() / "pick_octree_hqs.png";
  fs::remove(png);
  const CliResult hqs = runPointrast("render '" + octree_.string() + "' -o '" + png.string() + "'" + kCamera +
                                     kSize + " --method lod-hqs --pick 160,120");
  EXPECT_EQ(hqs.exitCode, 1) << hqs.err;
  EXPECT_NE(hqs.err.find("--pick on an octree reads the lod method's frame"), std::string::npos) << hqs.err;
  EXPECT_FALSE(fs::exists(png));
}

} // namespace

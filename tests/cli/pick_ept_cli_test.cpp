// render --method lod --pick X,Y --json on an EPT dataset shows every dimension of its schema: the record's
// fields, the LAS attributes under their keys (GpsTime as "gps_time", NumberOfReturns, ScanAngleRank) and
// any other dimension by its own name in "extra_bytes" (a scaled one as its value). The dataset is written
// here (binary data, one node) with attributes that differ from point to point, so that each picked point
// is checked against the values the test gave it.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;

constexpr int kSide = 64; // a kSide x kSide grid, one unit apart

// What the test stores for the point at grid (i, j).
struct Point {
  int32_t x, y, z; // 0.01 units
  uint16_t intensity;
  uint8_t classification;
  double gpsTime;
  uint8_t returns;
  float scanAngle;
  uint16_t deviation;
  int16_t amplitude; // scale 0.1
};

Point pointAt(int i, int j) {
  const int n = j * kSide + i;
  Point p;
  p.x = i * 100;
  p.y = j * 100;
  p.z = (n * 37) % 50;
  p.intensity = uint16_t(1000 + n);
  p.classification = uint8_t(n % 7);
  p.gpsTime = 250000.125 + n * 0.5;
  p.returns = uint8_t(1 + n % 5);
  p.scanAngle = float(-20.0 + (n % 41)) * 0.75f;
  p.deviation = uint16_t(60000 - n);
  p.amplitude = int16_t(n % 300 - 150);
  return p;
}

template <class T> void put(std::string& out, T v) {
  char bytes[sizeof v];
  std::memcpy(bytes, &v, sizeof v);
  out.append(bytes, sizeof v);
}

fs::path writeEpt() {
  const fs::path root = pointrast::test::cliTempDir() / "pick_ept";
  fs::remove_all(root);
  fs::create_directories(root / "ept-hierarchy");
  fs::create_directories(root / "ept-data");
  const nlohmann::json ept = {
      {"version", "1.0.0"},
      {"dataType", "binary"},
      {"hierarchyType", "json"},
      {"points", kSide * kSide},
      {"span", 128},
      {"bounds", {0, 0, 0, 64, 64, 64}},
      {"boundsConforming", {0, 0, 0, 63, 63, 0.5}},
      {"schema",
       {{{"name", "X"}, {"type", "signed"}, {"size", 4}, {"scale", 0.01}, {"offset", 0}},
        {{"name", "Y"}, {"type", "signed"}, {"size", 4}, {"scale", 0.01}, {"offset", 0}},
        {{"name", "Z"}, {"type", "signed"}, {"size", 4}, {"scale", 0.01}, {"offset", 0}},
        {{"name", "Intensity"}, {"type", "unsigned"}, {"size", 2}},
        {{"name", "Classification"}, {"type", "unsigned"}, {"size", 1}},
        {{"name", "GpsTime"}, {"type", "float"}, {"size", 8}},
        {{"name", "NumberOfReturns"}, {"type", "unsigned"}, {"size", 1}},
        {{"name", "ScanAngleRank"}, {"type", "float"}, {"size", 4}},
        {{"name", "Deviation"}, {"type", "unsigned"}, {"size", 2}},
        {{"name", "Amplitude"}, {"type", "signed"}, {"size", 2}, {"scale", 0.1}, {"offset", 0}}}}};
  std::ofstream(root / "ept.json") << ept.dump();
  std::ofstream(root / "ept-hierarchy" / "0-0-0-0.json") << nlohmann::json{{"0-0-0-0", kSide * kSide}}.dump();
  std::string data;
  for (int j = 0; j < kSide; ++j)
    for (int i = 0; i < kSide; ++i) {
      const Point p = pointAt(i, j);
      put(data, p.x);
      put(data, p.y);
      put(data, p.z);
      put(data, p.intensity);
      put(data, p.classification);
      put(data, p.gpsTime);
      put(data, p.returns);
      put(data, p.scanAngle);
      put(data, p.deviation);
      put(data, p.amplitude);
    }
  std::ofstream(root / "ept-data" / "0-0-0-0.bin", std::ios::binary) << data;
  return root;
}

TEST(PickEptCli, APickShowsEveryDimensionOfTheSchema) {
  const fs::path ept = writeEpt();
  const fs::path png = pointrast::test::cliTempDir() / "pick_ept.png";
  int checked = 0;
  for (const auto& [px, py] : {std::pair{80, 60}, {58, 38}, {102, 82}}) {
    const CliResult r =
        runPointrast("render '" + ept.string() + "' -o '" + png.string() +
                     "' --eye 31.5,31.5,100 --target 31.5,31.5,0 --up 0,1,0 --width 160 --height 120"
                     " --frames 1 --json -q --method lod --min-node-px 0 --pick " +
                     std::to_string(px) + "," + std::to_string(py));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_TRUE(j.is_object() && j.contains("pick")) << r.out << r.err;
    nlohmann::json p = j["pick"]["point"]; // a copy: a missing key reads as null, a failure, not an abort
    ASSERT_TRUE(p.is_object()) << "pixel " << px << "," << py << " shows no point: " << j["pick"].dump();
    const int i = int(std::lround(p["x"].get<double>())), jj = int(std::lround(p["y"].get<double>()));
    ASSERT_TRUE(i >= 0 && i < kSide && jj >= 0 && jj < kSide) << p.dump();
    const Point e = pointAt(i, jj);
    EXPECT_NEAR(p["z"].get<double>(), e.z * 0.01, 1e-9) << p.dump();
    EXPECT_EQ(p["intensity"], e.intensity);
    EXPECT_EQ(p["classification"], e.classification);
    EXPECT_EQ(p["node"], "r");
    EXPECT_EQ(p["gps_time"], e.gpsTime) << p.dump();
    EXPECT_EQ(p["number_of_returns"], e.returns) << p.dump();
    EXPECT_EQ(p["scan_angle"], double(e.scanAngle)) << p.dump();
    const nlohmann::json extra = {{"Deviation", e.deviation}, {"Amplitude", e.amplitude * 0.1 + 0.0}};
    EXPECT_EQ(p["extra_bytes"], extra) << p.dump();
    ++checked;
  }
  EXPECT_EQ(checked, 3);
}

} // namespace

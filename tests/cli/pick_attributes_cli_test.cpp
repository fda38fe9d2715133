// render --method lod --pick X,Y --json shows every attribute an octree keeps: for our Potree octrees
// (DEFAULT and BROTLI) and COPC files built from a LAS 1.4 point format 8 file with extra bytes, the picked
// point's GPS time, number of returns, scan angle, flags, NIR and extra bytes (by their descriptors'
// names) are those of the input's record at the picked coordinates, which the test finds in the file
// itself; for PotreeConverter's octrees, those of the record of las/autzen_trim.las they were made from.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "las_records_test_util.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using pointrast::test::las_records::Las;
using pointrast::test::las_records::load;
using pointrast::test::las_records::readLasFile;

// LAS 1.4 point format 8 (38-byte records: R15 Table 14, NIR at 36) with 3 extra bytes described by two
// extra bytes VLRs: "Deviation" (uint16 at 38) and "confidence" (uint8 at 40).
const char* const kExtra = "las/las_with_several_extra_byte_bloc.las";
const char* const kAutzen = "las/autzen_trim.las";
const std::string kSize = " --width 160 --height 120 --frames 1 --json -q --method lod --min-node-px 0";
// kExtra's points from above and south: they cover about pixels 45..100 x 30..110 of the image.
const std::string kExtraCamera = " --eye 484960,6632850,250 --target 484962,6632935,108 --up 0,0,1";
const int kExtraPixels[][2] = {{80, 60}, {60, 50}, {90, 40}, {70, 80}, {75, 100}, {55, 70}};
const std::string kAutzenCamera = " --eye 636300,848700,900 --target 636600,849200,450 --up 0,0,1";
const int kAutzenPixels[][2] = {{80, 60}, {50, 75}, {125, 45}, {100, 100}, {30, 105}, {150, 30}};

fs::path fresh(const std::string& name) {
  fs::path p = pointrast::test::cliTempDir() / name;
  fs::remove_all(p);
  return p;
}

nlohmann::json pickOf(const fs::path& octree, const std::string& camera, int x, int y) {
  const fs::path png = pointrast::test::cliTempDir() / "pick_attributes.png";
  const CliResult r = runPointrast("render '" + octree.string() + "' -o '" + png.string() + "'" + camera +
                                   kSize + " --pick " + std::to_string(x) + "," + std::to_string(y));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  if (!j.is_object() || !j.contains("pick")) {
    ADD_FAILURE() << "render printed " << r.out << r.err;
    return nlohmann::json::object();
  }
  return j["pick"];
}

const uint8_t* bytes(const std::string& record) {
  return reinterpret_cast<const uint8_t*>(record.data());
}

double world(const Las& las, const std::string& record, int axis) {
  return load<int32_t>(bytes(record) + 4 * axis) * las.scale[axis] + las.offset[axis];
}

// The attributes of a point format 8 record with kExtra's extra bytes, as the pick names them.
nlohmann::json expectedPf8(const std::string& record) {
  const uint8_t* r = bytes(record);
  nlohmann::json e;
  e["intensity"] = load<uint16_t>(r + 12);
  e["return_number"] = r[14] & 0x0F;
  e["number_of_returns"] = r[14] >> 4;
  e["classification_flags"] = r[15] & 0x0F;
  e["scanner_channel"] = (r[15] >> 4) & 3;
  e["scan_direction_flag"] = (r[15] >> 6) & 1;
  e["edge_of_flight_line"] = r[15] >> 7;
  e["classification"] = r[16];
  e["scan_angle"] = double(load<int16_t>(r + 18)) * 0.006;
  e["point_source_id"] = load<uint16_t>(r + 20);
  e["gps_time"] = load<double>(r + 22);
  e["nir"] = load<uint16_t>(r + 36);
  e["extra_bytes"] = {{"Deviation", load<uint16_t>(r + 38)}, {"confidence", r[40]}};
  return e;
}

// Picks pixels of an octree built from kExtra and checks each point against its record in the file.
void expectPf8Picks(const fs::path& octree, bool userData) {
  const Las in = readLasFile(pointrast::test::dataDir() / kExtra);
  ASSERT_EQ(in.pointFormat, 8);
  ASSERT_EQ(in.recordLength, 41);
  std::multimap<std::tuple<double, double, double>, size_t> byPosition;
  for (size_t i = 0; i < in.records.size(); ++i)
    byPosition.emplace(
        std::tuple{world(in, in.records[i], 0), world(in, in.records[i], 1), world(in, in.records[i], 2)}, i);
  int checked = 0;
  for (const auto& [x, y] : kExtraPixels) {
    const nlohmann::json pick = pickOf(octree, kExtraCamera, x, y);
    const nlohmann::json& p = pick["point"];
    if (!p.is_object()) continue;
    ++checked;
    for (const char* key : {"gps_time", "number_of_returns", "scan_angle", "nir", "classification_flags",
                            "scanner_channel", "scan_direction_flag", "edge_of_flight_line", "extra_bytes"})
      EXPECT_TRUE(p.contains(key)) << key << " missing from " << p.dump();
    EXPECT_EQ(p.contains("user_data"), userData) << p.dump();
    // The point is the record at its coordinates whose attributes it shows (several may share them).
    const auto [first, last] =
        byPosition.equal_range({p["x"].get<double>(), p["y"].get<double>(), p["z"].get<double>()});
    ASSERT_NE(first, last) << "not a point of the file: " << p.dump();
    nlohmann::json shown = p;
    for (const char* key : {"index", "node", "x", "y", "z", "color", "user_data"})
      shown.erase(key);
    bool found = false;
    std::string candidates;
    for (auto it = first; it != last && !found; ++it) {
      const std::string& record = in.records[it->second];
      const nlohmann::json expected = expectedPf8(record);
      found = shown == expected && (!userData || p["user_data"] == bytes(record)[17]);
      candidates += "\n  " + expected.dump();
    }
    EXPECT_TRUE(found) << "pixel " << x << "," << y << " shows " << shown.dump()
                       << "; the file's records there:" << candidates;
  }
  EXPECT_GE(checked, 4);
}

class PickAttributesCli : public ::testing::Test {
protected:
  static fs::path build(const std::string& name, const std::string& options) {
    const fs::path octree = fresh(name);
    const CliResult r = runPointrast("lod '" + (pointrast::test::dataDir() / kExtra).string() + "' -o '" +
                                     octree.string() + "' --no-color-filter -q" + options);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return octree;
  }
};

TEST_F(PickAttributesCli, PotreeDefaultShowsEveryAttributeOfTheRecord) {
  POINTRAST_REQUIRE_DATA(kExtra);
  // Every point's user data is 0 in this file: the octree leaves the field out.
  expectPf8Picks(build("pick_attr_default", ""), false);
}

TEST_F(PickAttributesCli, PotreeBrotliShowsEveryAttributeOfTheRecord) {
  POINTRAST_REQUIRE_DATA(kExtra);
  expectPf8Picks(build("pick_attr_brotli", " --encoding brotli"), false);
}

TEST_F(PickAttributesCli, CopcShowsEveryAttributeOfTheRecord) {
  POINTRAST_REQUIRE_DATA(kExtra);
  // A COPC node holds whole LAS records: the user data is there.
  expectPf8Picks(build("pick_attr.copc.laz", ""), true);
}

// LAS 1.2 point format 3 with 27 extra bytes in five fields: "Colors" uint16[3] (the deprecated array type
// 23) at 34, "Reserved" 7 undocumented bytes at 40, "Flags" int8[2] at 47, "Intensity" uint32 at 49,
// "Time" uint64 at 53. The pick lists arrays and undocumented bytes element by element.
TEST_F(PickAttributesCli, ExtraBytesArraysAndUndocumentedBytes) {
  const char* const input = "las/extrabytes.las";
  POINTRAST_REQUIRE_DATA(input);
  const Las in = readLasFile(pointrast::test::dataDir() / input);
  ASSERT_EQ(in.pointFormat, 3);
  ASSERT_EQ(in.recordLength, 61);
  const fs::path octree = fresh("pick_attr_extrabytes");
  const CliResult built = runPointrast("lod '" + (pointrast::test::dataDir() / input).string() + "' -o '" +
                                       octree.string() + "' --no-color-filter -q");
  ASSERT_EQ(built.exitCode, 0) << built.err;
  int checked = 0;
  // The default camera frames the whole cloud; at 40 x 30 most pixels near the middle show a point.
  for (const auto& [x, y] : {std::pair{20, 15}, {15, 12}, {25, 18}, {10, 15}, {30, 10}, {20, 20}}) {
    const fs::path png = pointrast::test::cliTempDir() / "pick_attributes_eb.png";
    const CliResult r =
        runPointrast("render '" + octree.string() + "' -o '" + png.string() +
                     "' --width 40 --height 30 --frames 1 --json -q --method lod --min-node-px 0 "
                     "--pick " +
                     std::to_string(x) + "," + std::to_string(y));
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json p = nlohmann::json::parse(r.out)["pick"]["point"];
    if (!p.is_object()) continue;
    ++checked;
    const std::string* record = nullptr;
    for (const std::string& candidate : in.records) {
      const double t = load<double>(bytes(candidate) + 20);
      if (world(in, candidate, 0) == p["x"].get<double>() &&
          world(in, candidate, 1) == p["y"].get<double>() &&
          world(in, candidate, 2) == p["z"].get<double>() && p.value("gps_time", -1.0) == t)
        record = &candidate;
    }
    ASSERT_NE(record, nullptr) << "no record of the file has the point's place and GPS time: " << p.dump();
    const uint8_t* b = bytes(*record);
    nlohmann::json expected = {
        {"number_of_returns", (b[14] >> 3) & 7}, {"scan_direction_flag", (b[14] >> 6) & 1},
        {"edge_of_flight_line", b[14] >> 7},     {"classification_flags", b[15] >> 5},
        {"scan_angle", int(int8_t(b[16]))},      {"user_data", b[17]}};
    nlohmann::json extra;
    extra["Colors"] = {load<uint16_t>(b + 34), load<uint16_t>(b + 36), load<uint16_t>(b + 38)};
    extra["Reserved"] = nlohmann::json::array();
    for (int k = 0; k < 7; ++k)
      extra["Reserved"].push_back(b[40 + k]);
    extra["Flags"] = {int(int8_t(b[47])), int(int8_t(b[48]))};
    extra["Intensity"] = load<uint32_t>(b + 49);
    extra["Time"] = load<uint64_t>(b + 53);
    expected["extra_bytes"] = extra;
    for (const auto& [key, value] : expected.items())
      EXPECT_EQ(p.value(key, nlohmann::json()), value) << key << " in " << p.dump();
    EXPECT_FALSE(p.contains("scanner_channel")) << "format 3 has no scanner channel: " << p.dump();
    EXPECT_FALSE(p.contains("nir")) << p.dump();
  }
  EXPECT_GE(checked, 4);
}

// An octree as PotreeConverter describes one: our octree's metadata.json without pointrast's generator and
// "lasAttributes" block. The attributes are found by their names and types alone: the flags from their
// four fields, "Deviation" and "confidence" as extra bytes fields of their own types.
TEST_F(PickAttributesCli, AttributesNamedAsPotreeConverterNamesThem) {
  POINTRAST_REQUIRE_DATA(kExtra);
  const fs::path octree = build("pick_attr_named", "");
  nlohmann::json m = nlohmann::json::parse(pointrast::test::slurp(octree / "metadata.json"));
  ASSERT_TRUE(m.contains("lasAttributes"));
  m.erase("lasAttributes");
  m["generator"] = "PotreeConverter 2.1";
  {
    std::ofstream out(octree / "metadata.json", std::ios::trunc);
    out << m.dump(2);
  }
  expectPf8Picks(octree, false);
}

// PotreeConverter truncates coordinates (up to one quantum, 0.01, below the LAS's): the record is the one
// within a quantum on every axis with the picked GPS time.
void expectPotreeConverterPicks(const std::string& folder) {
  const Las in = readLasFile(pointrast::test::dataDir() / kAutzen);
  ASSERT_EQ(in.pointFormat, 3);
  std::multimap<double, size_t> byTime;
  for (size_t i = 0; i < in.records.size(); ++i)
    byTime.emplace(load<double>(bytes(in.records[i]) + 20), i);
  const fs::path octree = pointrast::test::dataDir() / "potree" / folder;
  int checked = 0;
  for (const auto& [x, y] : kAutzenPixels) {
    const nlohmann::json pick = pickOf(octree, kAutzenCamera, x, y);
    const nlohmann::json& p = pick["point"];
    if (!p.is_object()) continue;
    ++checked;
    ASSERT_TRUE(p.contains("gps_time")) << p.dump();
    const std::string* record = nullptr;
    const auto [first, last] = byTime.equal_range(p["gps_time"].get<double>());
    for (auto it = first; it != last; ++it) {
      bool near = true;
      for (int a = 0; a < 3; ++a)
        near = near && std::abs(world(in, in.records[it->second], a) -
                                p[std::string(1, char('x' + a))].get<double>()) <= 1.5 * in.scale[a];
      if (near) record = &in.records[it->second];
    }
    ASSERT_NE(record, nullptr) << "no record of " << kAutzen
                               << " has the point's GPS time and place: " << p.dump();
    // Point format 3 (R15 Table 10): returns in byte 14, the scan angle rank an int8 at 16, user data 17.
    const uint8_t* r = bytes(*record);
    EXPECT_EQ(p["intensity"], load<uint16_t>(r + 12)) << p.dump();
    EXPECT_EQ(p["return_number"], r[14] & 7) << p.dump();
    EXPECT_EQ(p["number_of_returns"], (r[14] >> 3) & 7) << p.dump();
    EXPECT_EQ(p["classification"], r[15] & 31) << p.dump();
    EXPECT_EQ(p["scan_angle"], int(int8_t(r[16]))) << p.dump();
    EXPECT_EQ(p["user_data"], r[17]) << p.dump();
    EXPECT_EQ(p["point_source_id"], load<uint16_t>(r + 18)) << p.dump();
  }
  EXPECT_GE(checked, 4);
}

TEST(PickAttributesPotreeConverterCli, DefaultShowsTheSourceRecordsAttributes) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default/metadata.json");
  POINTRAST_REQUIRE_DATA(kAutzen);
  expectPotreeConverterPicks("autzen_trim_default");
}

TEST(PickAttributesPotreeConverterCli, BrotliShowsTheSourceRecordsAttributes) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_brotli/metadata.json");
  POINTRAST_REQUIRE_DATA(kAutzen);
  expectPotreeConverterPicks("autzen_trim_brotli");
}

} // namespace

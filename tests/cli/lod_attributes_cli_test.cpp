// `pointrast lod` keeps every attribute of a LAS input: an octree (Potree 2.0 or COPC) built with
// --no-color-filter and exported with `convert` gives back every input record byte for byte (GPS time,
// returns, flags, NIR, extra bytes), as a multiset, in the input's point format; in memory and out of
// core alike, and the same bytes from two builds.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "las_records_test_util.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::runPointrast;
using pointrast::test::slurp;
using pointrast::test::las_records::Las;
using pointrast::test::las_records::readLasFile;

// LAS 1.4 point format 8 with 3 extra bytes in two extra bytes VLRs, 16-bit RGB and NIR, GPS times and
// several returns per pulse.
const char* const kExtra = "las/las_with_several_extra_byte_bloc.las";

fs::path fresh(const std::string& name) {
  fs::path p = pointrast::test::cliTempDir() / name;
  fs::remove_all(p);
  return p;
}

std::vector<std::string> sorted(std::vector<std::string> records) {
  std::sort(records.begin(), records.end());
  return records;
}

// Builds an octree of the input with extra options, exports it, and checks the records.
void expectRoundTrip(const std::string& name, const std::string& options, bool outOfCore) {
  const fs::path input = pointrast::test::dataDir() / kExtra;
  const fs::path octree = fresh(name), back = fresh(name + ".las");
  const auto built = runPointrast("lod " + input.string() + " -o " + octree.string() +
                                  " --no-color-filter --leaf-points 5k --json " + options);
  ASSERT_EQ(built.exitCode, 0) << built.err;
  EXPECT_EQ(nlohmann::json::parse(built.out)["out_of_core"].get<bool>(), outOfCore) << built.out;
  const auto exported = runPointrast("convert " + octree.string() + " " + back.string() + " -q");
  ASSERT_EQ(exported.exitCode, 0) << exported.err;
  const Las in = readLasFile(input), out = readLasFile(back);
  EXPECT_EQ(out.pointFormat, in.pointFormat);
  ASSERT_EQ(out.recordLength, in.recordLength);
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(out.scale[a], in.scale[a]);
    EXPECT_EQ(out.offset[a], in.offset[a]);
  }
  ASSERT_EQ(out.records.size(), in.records.size());
  EXPECT_TRUE(sorted(out.records) == sorted(in.records)) << "the records differ";
}

TEST(LodAttributesCli, PotreeGivesBackEveryRecordInMemory) {
  POINTRAST_REQUIRE_DATA(kExtra);
  expectRoundTrip("lod_attr_mem", "", false);
}

TEST(LodAttributesCli, PotreeGivesBackEveryRecordOutOfCore) {
  POINTRAST_REQUIRE_DATA(kExtra);
  expectRoundTrip("lod_attr_ooc", "--memory 2M --threads 2", true);
}

TEST(LodAttributesCli, BrotliPotreeGivesBackEveryRecord) {
  POINTRAST_REQUIRE_DATA(kExtra);
  expectRoundTrip("lod_attr_brotli", "--encoding brotli", false);
}

TEST(LodAttributesCli, CopcGivesBackEveryRecordInMemory) {
  POINTRAST_REQUIRE_DATA(kExtra);
  expectRoundTrip("lod_attr_mem.copc.laz", "", false);
}

TEST(LodAttributesCli, CopcGivesBackEveryRecordOutOfCore) {
  POINTRAST_REQUIRE_DATA(kExtra);
  expectRoundTrip("lod_attr_ooc.copc.laz", "--memory 2M --threads 2", true);
}

TEST(LodAttributesCli, MetadataNamesTheAttributesAsPotreeConverter) {
  POINTRAST_REQUIRE_DATA(kExtra);
  const fs::path octree = fresh("lod_attr_names");
  ASSERT_EQ(
      runPointrast("lod " + (pointrast::test::dataDir() / kExtra).string() + " -q -o " + octree.string())
          .exitCode,
      0);
  const nlohmann::json m = nlohmann::json::parse(slurp(octree / "metadata.json"));
  std::vector<std::string> names;
  for (const auto& a : m["attributes"])
    names.push_back(a["name"].get<std::string>());
  for (const char* name :
       {"gps-time", "number of returns", "classification flags", "scan angle", "nir", "scanner channel",
        "scan direction flag", "edge of flight line", "Deviation", "confidence"})
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  // Every point's user data is 0 in this file: the field is left out (an export writes 0).
  EXPECT_EQ(std::find(names.begin(), names.end(), "user data"), names.end());
  // The GPS time range is the input's (format 8: a double at byte 22 of each record).
  const Las in = readLasFile(pointrast::test::dataDir() / kExtra);
  double lo = 1e300, hi = -1e300;
  for (const std::string& r : in.records) {
    const double t =
        pointrast::test::las_records::load<double>(reinterpret_cast<const uint8_t*>(r.data()) + 22);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  for (const auto& a : m["attributes"])
    if (a["name"] == "gps-time") {
      EXPECT_EQ(a["min"][0].get<double>(), lo);
      EXPECT_EQ(a["max"][0].get<double>(), hi);
    }
  EXPECT_EQ(m["lasAttributes"]["pointFormat"], 8);
  EXPECT_EQ(m["lasAttributes"]["extraBytes"], 3);
}

TEST(LodAttributesCli, TwoBuildsGiveTheSameBytes) {
  POINTRAST_REQUIRE_DATA(kExtra);
  const fs::path input = pointrast::test::dataDir() / kExtra;
  const fs::path a = fresh("lod_attr_det_a"), b = fresh("lod_attr_det_b");
  fs::create_directories(a);
  fs::create_directories(b);
  const std::string common = " --no-color-filter --leaf-points 5k -q ";
  ASSERT_EQ(runPointrast("lod " + input.string() + common + "--threads 2 -o " + (a / "o").string()).exitCode,
            0);
  ASSERT_EQ(runPointrast("lod " + input.string() + common + "--memory 2M -o " + (b / "o").string()).exitCode,
            0);
  for (const char* file : {"octree.bin", "hierarchy.bin", "metadata.json"})
    EXPECT_TRUE(slurp(a / "o" / file) == slurp(b / "o" / file)) << file;
  const fs::path c = fresh("lod_attr_det_c.copc.laz"), d = fresh("lod_attr_det_d.copc.laz");
  ASSERT_EQ(runPointrast("lod " + input.string() + common + "--threads 2 -o " + c.string()).exitCode, 0);
  ASSERT_EQ(runPointrast("lod " + input.string() + common + "--memory 2M -o " + d.string()).exitCode, 0);
  EXPECT_TRUE(slurp(c) == slurp(d));
}

} // namespace

// Test-side LAS reading for the CLI tests of filters and profiles: the header fields and raw records of a
// LAS file parsed by the test itself (ASPRS LAS 1.4 R15), LAZ and COPC records through the project's
// decoder, and the checks that a written file holds exactly an expected multiset of records.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/las/laz_reader.h"

namespace pointrast::test::las_records {

namespace fs = std::filesystem;

template <class T> T load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// A LAS file as the test reads it: the public header fields it needs (R15 Table 3) and the raw records.
struct Las {
  int pointFormat = 0;
  uint16_t recordLength = 0;
  uint64_t headerCount = 0;
  double scale[3], offset[3], max[3], min[3];
  std::vector<std::string> records;
};

inline Las readLasFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const auto* b = reinterpret_cast<const uint8_t*>(bytes.data());
  Las las;
  const int minor = b[25];
  const uint32_t pointOffset = load<uint32_t>(b + 96);
  las.pointFormat = b[104] & 0x3F;
  las.recordLength = load<uint16_t>(b + 105);
  las.headerCount = load<uint32_t>(b + 107);
  if (minor >= 4 && las.headerCount == 0) las.headerCount = load<uint64_t>(b + 247);
  for (int a = 0; a < 3; ++a) {
    las.scale[a] = load<double>(b + 131 + 8 * a);
    las.offset[a] = load<double>(b + 155 + 8 * a);
    las.max[a] = load<double>(b + 179 + 16 * a);
    las.min[a] = load<double>(b + 187 + 16 * a);
  }
  for (uint64_t i = 0; i < las.headerCount; ++i)
    las.records.push_back(bytes.substr(pointOffset + i * las.recordLength, las.recordLength));
  return las;
}

// The records of a LAS file, or of a LAZ/COPC file as the project's LAZ decoder gives them.
inline Las readInput(const fs::path& path) {
  if (path.extension() != ".laz") return readLasFile(path);
  io::detail::InputFile file(path);
  const io::detail::LasHeader hd = io::detail::readLasHeader(file, true);
  Las las;
  las.pointFormat = hd.pointFormat;
  las.recordLength = hd.recordLength;
  for (int a = 0; a < 3; ++a) {
    las.scale[a] = hd.scale[a];
    las.offset[a] = hd.offset[a];
  }
  const std::vector<uint8_t> raw = io::readLazRecords(path);
  for (size_t at = 0; at + hd.recordLength <= raw.size(); at += hd.recordLength)
    las.records.emplace_back(reinterpret_cast<const char*>(raw.data() + at), hd.recordLength);
  las.headerCount = las.records.size();
  return las;
}

// One record's fields, read the way R15 section 2.6 lays them out.
struct Fields {
  double x, y, z;
  unsigned intensity, returnNumber, returns, classification, source;
  double gps;
};

inline Fields fieldsOf(const Las& las, const std::string& record) {
  const auto* r = reinterpret_cast<const uint8_t*>(record.data());
  Fields f;
  f.x = load<int32_t>(r) * las.scale[0] + las.offset[0];
  f.y = load<int32_t>(r + 4) * las.scale[1] + las.offset[1];
  f.z = load<int32_t>(r + 8) * las.scale[2] + las.offset[2];
  f.intensity = load<uint16_t>(r + 12);
  if (las.pointFormat >= 6) {
    f.returnNumber = r[14] & 15, f.returns = r[14] >> 4, f.classification = r[16],
    f.source = load<uint16_t>(r + 20);
    f.gps = load<double>(r + 22);
  } else {
    f.returnNumber = r[14] & 7, f.returns = (r[14] >> 3) & 7, f.classification = r[15] & 31;
    f.source = load<uint16_t>(r + 18);
    f.gps = las.pointFormat == 1 || las.pointFormat == 3 ? load<double>(r + 20) : 0;
  }
  return f;
}

using Rule = std::function<bool(const Fields&)>;

inline std::vector<std::string> select(const Las& las, const Rule& rule) {
  std::vector<std::string> out;
  for (const std::string& r : las.records)
    if (rule(fieldsOf(las, r))) out.push_back(r);
  std::sort(out.begin(), out.end());
  return out;
}

// The written file holds exactly `expected` (as a multiset), and its header's count and bounds describe it.
inline void expectLasHolds(const fs::path& path, const std::vector<std::string>& expected) {
  const Las out = readLasFile(path);
  std::vector<std::string> got = out.records;
  std::sort(got.begin(), got.end());
  EXPECT_EQ(out.headerCount, expected.size());
  EXPECT_TRUE(got == expected) << got.size() << " records written, " << expected.size() << " expected";
  if (got.empty()) return;
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const std::string& r : out.records) {
    const Fields f = fieldsOf(out, r);
    const double v[3] = {f.x, f.y, f.z};
    for (int a = 0; a < 3; ++a)
      lo[a] = std::min(lo[a], v[a]), hi[a] = std::max(hi[a], v[a]);
  }
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(out.min[a], lo[a], out.scale[a]) << "axis " << a;
    EXPECT_NEAR(out.max[a], hi[a], out.scale[a]) << "axis " << a;
  }
}

inline void expectOneLineFailure(const CliResult& r, const fs::path& out, const std::string& mentions) {
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_FALSE(r.signaled);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(mentions), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out)) << out;
  EXPECT_FALSE(fs::exists(io::detail::partialPath(out))) << out;
}

} // namespace pointrast::test::las_records

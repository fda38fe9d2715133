// COPC files written by the octree builder, read by an independent reader: copc.js (npm "copc", decoding
// through laz-perf) run by node through tests/web/copc_nodes.mjs walks every hierarchy page and decodes
// every node; each node's count and points (hashed as sorted text lines) must be those of the same node in
// the Potree folder of the same build. In CI (CI=true) a missing node or copc package fails the tests.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <set>
#include <sstream>

#include "cli/las_records_test_util.h"
#include "io/copc_build_test_util.h"
#include "io/io_test_util.h"
#include "io/sha256.h"
#include "io/writer.h"

#include "cloud/generate.h"

namespace {

using namespace pointrast;
using namespace copctest;

const std::string kWebDir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";

std::string run(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) {
    status = -1;
    return out;
  }
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0)
    out.append(buffer, n);
  status = pclose(pipe);
  return out;
}

// What copc_nodes.mjs prints for the nodes of the Potree build, as the COPC file must hold them: point
// format 6/7 records of the same points (return number 1 where the octree keeps none).
std::string expectedLines(const std::filesystem::path& potreeDir, size_t pages) {
  std::unique_ptr<lod::NodeSource> source = io::openPotree(potreeDir);
  const RecordFields& f = source->metadata().fields;
  const Nodes nodes = readNodes(*source);
  std::ostringstream out;
  out << "COPC " << source->metadata().pointCount << " " << nodes.size() << " " << pages << "\n";
  for (const auto& [key, records] : nodes) {
    std::vector<std::string> lines;
    for (const PointRecord& r : records) {
      const unsigned rn = (f.returnNumber ? r.returnNumber : 1) & 0x0F;
      std::ostringstream line;
      line << r.x << " " << r.y << " " << r.z << " " << r.intensity << " " << rn << " "
           << unsigned(r.classification) << " " << r.pointSourceId << " " << r.rgb[0] << " " << r.rgb[1]
           << " " << r.rgb[2];
      lines.push_back(line.str());
    }
    std::sort(lines.begin(), lines.end());
    std::string joined;
    for (size_t i = 0; i < lines.size(); ++i)
      joined += (i ? "\n" : "") + lines[i];
    out << key.level << "-" << key.x << "-" << key.y << "-" << key.z << " " << records.size() << " "
        << iotest::sha256Hex(reinterpret_cast<const uint8_t*>(joined.data()), joined.size()) << "\n";
  }
  return out.str();
}

class CopcJs : public ::testing::Test {
protected:
  void SetUp() override {
    int status = 0;
    run("node --version >/dev/null 2>&1", status);
    const bool node = status == 0;
    const bool copc = std::filesystem::exists(kWebDir + "/node_modules/copc/package.json");
    if (node && copc) return;
    const char* ci = std::getenv("CI");
    const std::string missing = !node ? "node is not installed (scripts/install-deps.sh)"
                                      : "copc.js is not installed: run scripts/web-test-setup.sh";
    if (ci && std::string(ci) == "true")
      FAIL() << missing;
    else
      GTEST_SKIP() << missing;
  }

  void expectCopcJsReads(const Builds& b) {
    const std::optional<io::CopcSummary> summary = io::summarizeCopc(b.copc);
    ASSERT_TRUE(summary);
    int status = 0;
    const std::string out =
        run("cd '" + kWebDir + "' && node copc_nodes.mjs '" + b.copc.string() + "' 2>&1", status);
    ASSERT_EQ(status, 0) << "copc.js could not read " << b.copc << ":\n" << out;
    EXPECT_EQ(out, expectedLines(b.potree, summary->pages));
  }
};

TEST_F(CopcJs, ReadsEveryNodeOfAGeneratedCloud) {
  iotest::TempDir dir;
  GenerateOptions g;
  g.points = 40'000;
  g.progress = false;
  io::writeLas(dir / "t.las", generateScene(Scene::Terrain, g), io::LasFlavor::Las12Pf2);
  io::LodBuildOptions options;
  options.leafPoints = 2'000;
  io::CopcWriteOptions copc;
  copc.hierarchyStepSize = 1;
  expectCopcJsReads(buildBoth({dir / "t.las"}, dir.path(), options, copc));
}

TEST_F(CopcJs, ReadsEveryNodeOfAutzen) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  io::LodBuildOptions options;
  options.leafPoints = 4'000;
  expectCopcJsReads(buildBoth({iotest::data("las/autzen_trim.las")}, dir.path(), options));
}

} // namespace

namespace {

// One LAS file's point records as copc_nodes.mjs --records describes a COPC file's: the count, the record
// length, the SHA-256 of the sorted lowercase hex records joined by "\n"; the extra bytes dimensions' names
// (from the LASF_Spec 4 VLRs), and GpsTime and each extra bytes dimension summed over every point.
struct LasRecords {
  std::string line; // "RECORDS COUNT LENGTH SHA256"
  std::vector<std::string> extraNames;
  std::map<std::string, double> sums;
  std::set<std::string> scaled; // dimensions whose descriptor states a scale or an offset
};

template <typename T> T le(const uint8_t* b, size_t at) {
  T v;
  std::memcpy(&v, b + at, sizeof v);
  return v;
}

LasRecords lasRecords(const std::filesystem::path& path) {
  const std::vector<uint8_t> file = iotest::readBytes(path);
  const uint8_t* b = file.data();
  const uint16_t headerSize = le<uint16_t>(b, 94);
  const uint32_t vlrs = le<uint32_t>(b, 100);
  const test::las_records::Las las = test::las_records::readLasFile(path);
  LasRecords r;
  struct Extra {
    std::string name;
    uint8_t type;
    size_t at; // in the record
  };
  std::vector<Extra> extras;
  static const size_t kSize[11] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
  size_t at = 38; // point format 8's record; the extra bytes follow it
  for (size_t v = 0, p = headerSize; v < vlrs; ++v) {
    const std::string user(reinterpret_cast<const char*>(b + p + 2), 16);
    const uint16_t id = le<uint16_t>(b, p + 18), bytes = le<uint16_t>(b, p + 20);
    if (user.rfind("LASF_Spec", 0) == 0 && id == 4)
      for (size_t d = p + 54; d + 192 <= p + 54 + bytes; d += 192) {
        Extra e{std::string(reinterpret_cast<const char*>(b + d + 4)), b[d + 2], at};
        e.name = e.name.substr(0, std::min<size_t>(e.name.size(), 32));
        if (b[d + 3] & 0x18) r.scaled.insert(e.name);
        at += e.type ? kSize[e.type] : b[d + 3];
        extras.push_back(e);
        r.extraNames.push_back(e.name);
      }
    p += 54 + bytes;
  }
  std::vector<std::string> hex;
  static const char* kDigits = "0123456789abcdef";
  for (const std::string& record : las.records) {
    const auto* rec = reinterpret_cast<const uint8_t*>(record.data());
    std::string h;
    for (const uint8_t byte : record)
      h += {kDigits[byte >> 4], kDigits[byte & 15]};
    hex.push_back(h);
    r.sums["GpsTime"] += le<double>(rec, 22);
    for (const Extra& e : extras) {
      double v = 0;
      switch (e.type) {
      case 1:
        v = rec[e.at];
        break;
      case 2:
        v = int8_t(rec[e.at]);
        break;
      case 3:
        v = le<uint16_t>(rec, e.at);
        break;
      case 4:
        v = le<int16_t>(rec, e.at);
        break;
      case 5:
        v = le<uint32_t>(rec, e.at);
        break;
      case 6:
        v = le<int32_t>(rec, e.at);
        break;
      case 7:
        v = double(le<uint64_t>(rec, e.at));
        break;
      case 8:
        v = double(le<int64_t>(rec, e.at));
        break;
      case 9:
        v = le<float>(rec, e.at);
        break;
      case 10:
        v = le<double>(rec, e.at);
        break;
      default:
        break;
      }
      r.sums[e.name] += v;
    }
  }
  std::sort(hex.begin(), hex.end());
  std::string joined;
  for (size_t i = 0; i < hex.size(); ++i)
    joined += (i ? "\n" : "") + hex[i];
  r.line = "RECORDS " + std::to_string(las.records.size()) + " " + std::to_string(las.recordLength) + " " +
           iotest::sha256Hex(reinterpret_cast<const uint8_t*>(joined.data()), joined.size());
  return r;
}

// A point format 8 file with GPS time, NIR and two extra bytes blocks, built into COPC with exact colors:
// copc.js decodes every node, and the records it gets are the input's, byte for byte, as a multiset; it
// parses the extra bytes descriptors the file carries and reads the same values through them.
TEST_F(CopcJs, ReadsEveryAttributeAndTheExtraBytesOfAnExactArchive) {
  POINTRAST_REQUIRE_DATA("las/las_with_several_extra_byte_bloc.las");
  const std::filesystem::path input = iotest::data("las/las_with_several_extra_byte_bloc.las");
  iotest::TempDir dir;
  io::LodBuildOptions options;
  options.leafPoints = 5'000;
  options.averageColors = false;
  options.progress = false;
  io::CopcWriteOptions copc;
  copc.hierarchyStepSize = 1;
  const std::filesystem::path out = dir / "exact.copc.laz";
  io::buildCopc({input}, out, options, copc);
  int status = 0;
  const std::string text =
      run("cd '" + kWebDir + "' && node copc_nodes.mjs --records '" + out.string() + "' 2>&1", status);
  ASSERT_EQ(status, 0) << "copc.js could not read " << out << ":\n" << text;
  const LasRecords expected = lasRecords(input);
  ASSERT_EQ(expected.extraNames.size(), 2u) << "the file has two extra bytes blocks";
  std::istringstream lines(text);
  std::string line;
  ASSERT_TRUE(std::getline(lines, line));
  EXPECT_EQ(line, expected.line) << "the records copc.js decoded are not the input's";
  ASSERT_TRUE(std::getline(lines, line));
  std::string eb = "EB";
  for (const std::string& name : expected.extraNames)
    eb += " " + name;
  EXPECT_EQ(line, eb);
  size_t sums = 0, compared = 0;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::string tag, name;
    double sum = 0;
    ASSERT_TRUE(in >> tag >> name >> sum) << line;
    ASSERT_EQ(tag, "SUM");
    ASSERT_TRUE(expected.sums.count(name)) << name;
    ++sums;
    // copc.js 0.0.8 reads a descriptor's scale and offset big-endian: a scaled dimension's values are its
    // own, not the file's. Unscaled ones must agree.
    if (expected.scaled.count(name)) continue;
    ++compared;
    EXPECT_NEAR(sum, expected.sums.at(name), 1e-9 * std::max(1.0, std::abs(expected.sums.at(name)))) << name;
  }
  EXPECT_EQ(sums, expected.sums.size());
  EXPECT_GE(compared, 2u) << "GPS time and at least one extra bytes dimension compared";
}

} // namespace

// `convert` with filters on real files: the points written are exactly those the test selects
// itself from the input's records (its own field parsing and rules, not the product's filter code), for
// LAS, LAS 1.4, COPC and an octree; clips skip whole nodes; a filter on an attribute the input lacks
// fails with one line.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "io/copc_ept/copc.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/las/laz_reader.h"
#include "io/potree/potree.h"
#include "las_records_test_util.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using namespace pointrast;
using namespace pointrast::test::las_records;

const fs::path kData = pointrast::test::dataDir();

bool inBox(const Fields& f, double x0, double y0, double z0, double x1, double y1, double z1) {
  return x0 <= f.x && f.x <= x1 && y0 <= f.y && f.y <= y1 && z0 <= f.z && f.z <= z1;
}

// Even-odd: the number of edges a ray towards +x crosses.
bool inPolygon(const std::vector<double>& xy, double x, double y) {
  bool inside = false;
  const size_t n = xy.size() / 2;
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const double xi = xy[2 * i], yi = xy[2 * i + 1], xj = xy[2 * j], yj = xy[2 * j + 1];
    if ((yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}

struct Case {
  const char* name;
  const char* file;
  std::string options;
  Rule rule;
};

class ConvertFilterCli : public ::testing::TestWithParam<Case> {};

TEST_P(ConvertFilterCli, WritesExactlyThePointsThatPass) {
  const Case& c = GetParam();
  POINTRAST_REQUIRE_DATA(c.file);
  const fs::path in = kData / c.file;
  const fs::path out = pointrast::test::cliTempDir() / (std::string(c.name) + ".las");
  fs::remove(out);
  const CliResult r = runPointrast("convert -q " + in.string() + " " + out.string() + " " + c.options);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Las input = readInput(in);
  const std::vector<std::string> expected = select(input, c.rule);
  EXPECT_GT(expected.size(), 0u) << "a case must keep some points";
  EXPECT_LT(expected.size(), input.records.size()) << "a case must drop some points";
  expectLasHolds(out, expected);
}

const std::vector<double> kPolygon = {636200, 849000, 636800, 849100, 636500, 849450};

INSTANTIATE_TEST_SUITE_P(
    Filters, ConvertFilterCli,
    ::testing::Values(
        Case{"box", "las/autzen_trim.las", "--clip-box 636300,849000,400,636700,849300,600",
             [](const Fields& f) { return inBox(f, 636300, 849000, 400, 636700, 849300, 600); }},
        Case{"two_boxes_outside", "las/autzen_trim.las",
             "--clip-box 636300,849000,400,636700,849300,600 --clip-box 637000,849400,0,637100,849500,1000 "
             "--clip-mode outside",
             [](const Fields& f) {
               return !inBox(f, 636300, 849000, 400, 636700, 849300, 600) &&
                      !inBox(f, 637000, 849400, 0, 637100, 849500, 1000);
             }},
        Case{"polygon_z", "las/autzen_trim.las",
             "--clip-polygon 636200,849000,636800,849100,636500,849450 --clip-z 400,430",
             [](const Fields& f) { return f.z >= 400 && f.z <= 430 && inPolygon(kPolygon, f.x, f.y); }},
        Case{"classes_last", "las/autzen_trim.las", "--classes 2,5-6 --returns last",
             [](const Fields& f) {
               return (f.classification == 2 || f.classification == 5 || f.classification == 6) &&
                      f.returnNumber != 0 && f.returnNumber == f.returns;
             }},
        Case{"first_intensity", "las/autzen_trim.las", "--returns first --intensity 20,120",
             [](const Fields& f) { return f.returnNumber == 1 && f.intensity >= 20 && f.intensity <= 120; }},
        Case{"only_gps", "las/autzen_trim.las", "--returns only --gps-time 245380,245383",
             [](const Fields& f) {
               return f.returnNumber != 0 && f.returns == 1 && f.gps >= 245380 && f.gps <= 245383;
             }},
        Case{"las14_pf7", "las/autzen_trim_7.las",
             "--classes 1 --returns first --clip-box 636300,849000,0,637000,849500,1000",
             [](const Fields& f) {
               return f.classification == 1 && f.returnNumber == 1 &&
                      inBox(f, 636300, 849000, 0, 637000, 849500, 1000);
             }},
        Case{"source_ids", "las/mvk-thin.las", "--source-ids 2003,2005",
             [](const Fields& f) { return f.source == 2003 || f.source == 2005; }},
        Case{"copc", "laz/lone-star.copc.laz", "--clip-box 515368,4918340,2300,515380,4918360,2400",
             [](const Fields& f) { return inBox(f, 515368, 4918340, 2300, 515380, 4918360, 2400); }}),
    [](const ::testing::TestParamInfo<Case>& param) { return std::string(param.param.name); });

// Statistics line "N of M nodes skipped by the clip".
std::pair<long, long> skippedNodes(const std::string& out) {
  const size_t at = out.find(" nodes skipped by the clip");
  if (at == std::string::npos) return {-1, -1};
  const size_t start = out.rfind('\n', at) == std::string::npos ? 0 : out.rfind('\n', at) + 1;
  long n = -1, m = -1;
  std::sscanf(out.c_str() + start, "%ld of %ld", &n, &m);
  return {n, m};
}

TEST(ConvertFilterCliNodes, CopcClipSkipsWholeNodes) {
  POINTRAST_REQUIRE_DATA("laz/lone-star.copc.laz");
  const fs::path out = pointrast::test::cliTempDir() / "copc_nodes.las";
  const CliResult r = runPointrast("convert " + (kData / "laz/lone-star.copc.laz").string() + " " +
                                   out.string() + " --clip-box 515368,4918340,2300,515380,4918360,2400");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto [skipped, nodes] = skippedNodes(r.out);
  long fileNodes = 0;
  std::unique_ptr<lod::NodeSource> source = io::openCopc(kData / "laz/lone-star.copc.laz");
  lod::forEachNode(*source, [&](const lod::NodeInfo&) { return ++fileNodes > 0; });
  EXPECT_EQ(nodes, fileNodes) << r.out;
  EXPECT_GT(skipped, 0) << r.out;
  EXPECT_LT(skipped, nodes) << r.out;
}

// A Potree octree: the expected points come from every node as the project's reader serves them.
TEST(ConvertFilterCliNodes, OctreeClipAndClassesSkipNodes) {
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default");
  const fs::path in = kData / "potree/autzen_trim_default";
  const fs::path out = pointrast::test::cliTempDir() / "octree_filtered.las";
  const CliResult r = runPointrast("convert " + in.string() + " " + out.string() +
                                   " --clip-box 636300,849000,400,636700,849300,600 --classes 2");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto [skipped, nodes] = skippedNodes(r.out);
  EXPECT_EQ(nodes, 93) << r.out;
  EXPECT_GT(skipped, 10) << r.out;

  std::unique_ptr<lod::NodeSource> source = io::openPotree(in);
  const lod::OctreeMetadata& meta = source->metadata();
  std::vector<std::array<int64_t, 5>> expected, got;
  uint64_t total = 0;
  lod::forEachNode(*source, [&](const lod::NodeInfo& node) {
    for (const PointRecord& p : source->readNode(node)) {
      ++total;
      const double x = p.x * meta.scale.x + meta.offset.x, y = p.y * meta.scale.y + meta.offset.y,
                   z = p.z * meta.scale.z + meta.offset.z;
      if (p.classification == 2 && 636300 <= x && x <= 636700 && 849000 <= y && y <= 849300 && 400 <= z &&
          z <= 600)
        expected.push_back({p.x, p.y, p.z, p.classification, p.intensity});
    }
    return true;
  });
  const Las las = readLasFile(out);
  for (const std::string& rec : las.records) {
    const Fields f = fieldsOf(las, rec);
    // Back to the octree's integers: the export keeps them (same scale and offset).
    got.push_back({std::llround((f.x - meta.offset.x) / meta.scale.x),
                   std::llround((f.y - meta.offset.y) / meta.scale.y),
                   std::llround((f.z - meta.offset.z) / meta.scale.z), f.classification, f.intensity});
  }
  std::sort(expected.begin(), expected.end());
  std::sort(got.begin(), got.end());
  EXPECT_GT(expected.size(), 100u);
  EXPECT_LT(expected.size(), total);
  EXPECT_EQ(las.headerCount, expected.size());
  EXPECT_TRUE(got == expected) << got.size() << " written, " << expected.size() << " expected";
}

TEST(ConvertFilterCliErrors, MissingAttributeIsOneLine) {
  POINTRAST_REQUIRE_DATA("las/permutations/1.2_0.las");
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default");
  const fs::path out = pointrast::test::cliTempDir() / "missing.las";
  fs::remove(out);
  // Point format 0 holds no GPS time; an octree's records hold no number of returns.
  expectOneLineFailure(runPointrast("convert -q " + (kData / "las/permutations/1.2_0.las").string() + " " +
                                    out.string() + " --gps-time 0,1"),
                       out, "--gps-time");
  expectOneLineFailure(runPointrast("convert -q " + (kData / "potree/autzen_trim_default").string() + " " +
                                    out.string() + " --returns last"),
                       out, "number of returns");
  expectOneLineFailure(runPointrast("convert -q " + (kData / "las/permutations/1.2_0.las").string() + " " +
                                    out.string() + " --classes 2,300"),
                       out, "--classes");
  expectOneLineFailure(runPointrast("convert -q " + (kData / "las/permutations/1.2_0.las").string() + " " +
                                    out.string() + " --clip-box 1,2,3"),
                       out, "--clip-box");
}

} // namespace

// COPC files written by the octree builder, read by an independent reader: copc.js (npm "copc", decoding
// through laz-perf) run by node through tests/web/copc_nodes.mjs walks every hierarchy page and decodes
// every node; each node's count and points (hashed as sorted text lines) must be those of the same node in
// the Potree folder of the same build. In CI (CI=true) a missing node or copc package fails the tests.
#include <cstdio>
#include <cstdlib>
#include <sstream>

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

// The vr2022 suite on lavapipe at a tiny scale, with its octree built by the command line's octree cache (the
// octree builder of `pointrast lod`) into a folder and reused by a second run:
// every configuration measured as a stereo pass and as mono renders, the stereo pass drawing at least what
// each eye draws alone, and the three reports written with the targets.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "bench/octree_cache.h"
#include "bench/suites.h"
#include "bench/vr_report.h"
#include "bench/vr_suite.h"
#include "gpu/gpu_fixture.h"

namespace {

using namespace pointrast;
using namespace pointrast::bench;

std::filesystem::path scratch(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("pointrast-vr-bench-" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(VrSuite, SharesPaper2022sStandInAndItsOctree) {
  const std::vector<Dataset> vr = suiteDatasets("vr2022", 1.0, 1);
  ASSERT_EQ(vr.size(), 1u);
  EXPECT_EQ(vr[0].points, 529'000'000u);
  EXPECT_EQ(vr[0].name, suiteDatasets("paper2022", 1.0, 1)[2].name);
  EXPECT_TRUE(isVrSuite("vr2022"));
  EXPECT_EQ(suiteDefaults("vr2022").width, 2478u);
  EXPECT_EQ(suiteDefaults("vr2022").height, 2740u);
}

class VrBench : public test::GpuTest {};

TEST_F(VrBench, TinySuiteMeasuresStereoAgainstMonoAndWritesItsReports) {
  VrSuiteConfig config;
  config.datasets = suiteDatasets("vr2022", 30'000.0 / 529e6, 1);
  config.width = 48;
  config.height = 52;
  config.frames = 1;
  config.minNodePx = 20; // a few levels of the tiny octree
  config.copyBytes = 1 << 20;
  config.copyRepeats = 1;
  config.progress = false;
  const std::filesystem::path octrees = scratch("octrees");
  OctreeCacheOptions cache;
  cache.dir = octrees;
  cache.threads = 2;
  cache.progress = false;
  config.octrees = octreeCache(cache);
  const VrSuiteRun run = runVrSuite(*context, config);
  ASSERT_EQ(run.datasets.size(), 1u);
  ASSERT_FALSE(run.datasets[0].skipped) << run.datasets[0].reason;
  ASSERT_EQ(run.octrees.size(), 1u);
  EXPECT_FALSE(run.octrees[0].second.reused);
  EXPECT_EQ(run.octrees[0].second.points, config.datasets[0].points);
  EXPECT_TRUE(run.stopped.empty()) << run.stopped;
  ASSERT_EQ(run.results.size(), config.views.size() * (2 * vrCases().size() - 1));
  for (const VrResult& r : run.results) {
    const std::string what = r.caseName + (r.stereo ? " stereo" : " mono");
    ASSERT_TRUE(r.ok()) << what << ": " << r.reason;
    const VrCase& c = *std::find_if(vrCases().begin(), vrCases().end(),
                                    [&](const VrCase& k) { return k.name == r.caseName; });
    EXPECT_EQ(r.passes.size(), r.stereo ? 1u : c.oneEye ? 1u : 2u) << what;
    EXPECT_GT(r.medianMs, 0.0) << what;
    EXPECT_EQ(r.passes[0].post.has_value(), c.dilate) << what;
    if (!r.stereo || c.oneEye) continue;
    // One selection for both eyes: at least each eye's own.
    for (const VrResult& m : run.results) {
      if (m.stereo || m.caseName != r.caseName || m.view != r.view) continue;
      for (const FrameStats& eye : m.passes)
        EXPECT_GE(r.passes[0].lod->pointsDrawn, eye.lod->pointsDrawn) << what;
    }
  }
  ReportInfo info;
  info.name = "vr-smoke";
  info.title = "vr2022 (tiny)";
  const std::filesystem::path out = scratch("reports");
  writeVrSuiteReports(run, info, out);
  std::ifstream json(out / "vr-smoke.json");
  const nlohmann::json j = nlohmann::json::parse(json);
  EXPECT_EQ(j["results"].size(), run.results.size());
  EXPECT_EQ(j["settings"]["targets"]["vr_frame_ms"], kVrFrameTargetMs);
  std::ifstream mdFile(out / "vr-smoke.md");
  const std::string md((std::istreambuf_iterator<char>(mdFile)), std::istreambuf_iterator<char>());
  EXPECT_NE(md.find("| vr frame |"), std::string::npos) << md;
  EXPECT_NE(md.find("speed-up"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(out / "vr-smoke.svg"));
  // A second run finds the octree in the folder.
  config.views = {View::Overview};
  const VrSuiteRun again = runVrSuite(*context, config);
  ASSERT_EQ(again.octrees.size(), 1u);
  EXPECT_TRUE(again.octrees[0].second.reused);
  EXPECT_GT(again.octrees[0].second.buildSeconds, 0.0) << "the build's time kept beside the octree";
  std::filesystem::remove_all(octrees.parent_path());
}

} // namespace

// The sphere benchmark runner on whatever device is present (lavapipe in CI): a tiny matrix end to end,
// with a data set too large to fit, a layout the set cannot be held in, options the device may lack, and
// the three reports of its run. Timings are never asserted.
#include <algorithm>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bench/report.h"
#include "bench/sphere_runner.h"
#include "gpu/gpu_fixture.h"

namespace {

using namespace pointrast;
using test::GpuTest;

class SphereBenchGpu : public GpuTest {};

TEST_F(SphereBenchGpu, TinyMatrixMeasuresSkipsAndReports) {
  bench::SphereBenchConfig config;
  bench::Dataset tiny{"tiny", "tiny (particles-drops, 3k)", "particles-drops", 3000, 1, false};
  // More particles than any device holds: skipped from the estimate alone, never generated.
  bench::Dataset huge{"huge", "huge (particles-laser, 1T)", "particles-laser", uint64_t(1) << 40, 1, false};
  config.datasets = {huge, tiny};
  config.methods = {SphereMethod::Compute, SphereMethod::Strip};
  config.layouts = {ParticleLayout::Aos, ParticleLayout::Xyz};
  config.billboards = {SphereBillboard::Screen, SphereBillboard::Camera};
  config.conservative = {false, true};
  config.orbits = {bench::Orbit::Short, bench::Orbit::Long};
  config.cameras = 3;
  config.width = 64;
  config.height = 36;
  config.frames = 1;
  config.copyBytes = 1 << 20;
  config.copyRepeats = 2;
  config.progress = false;
  std::vector<std::string> notes;
  size_t calls = 0, lastTotal = 0;
  bench::SphereBenchCallbacks callbacks;
  callbacks.onNote = [&](const std::string& line) { notes.push_back(line); };
  callbacks.onResult = [&](const bench::SphereBenchRun& run, const bench::SphereResult&, size_t done,
                           size_t total) {
    EXPECT_GT(run.copy.bytesPerSecond, 0.0);
    EXPECT_EQ(done, ++calls);
    lastTotal = total;
  };
  bench::SphereBenchRun run = bench::runSphereBench(*context, config, callbacks);
  ASSERT_EQ(run.datasets.size(), 2u);
  EXPECT_TRUE(run.datasets[0].skipped);
  EXPECT_NE(run.datasets[0].reason.find("does not fit: needs "), std::string::npos) << run.datasets[0].reason;
  EXPECT_FALSE(run.datasets[1].skipped);
  EXPECT_EQ(run.datasets[1].points, 3000u);
  // aos only (the scene has per-particle colors: no xyz) x 2 orbits x (compute + strip x 2 x 2).
  EXPECT_EQ(run.results.size(), 2u * 5);
  EXPECT_EQ(calls, run.results.size());
  EXPECT_EQ(lastTotal, run.results.size());
  EXPECT_TRUE(std::any_of(notes.begin(), notes.end(), [](const std::string& n) {
    return n.rfind("tiny (particles-drops, 3k): layout xyz skipped: ", 0) == 0;
  }));
  EXPECT_EQ(run.skippedLayouts.size(), 2u) << "xyz of both data sets";
  ASSERT_EQ(run.cameras.size(), 2u);
  EXPECT_EQ(run.cameras[0].cameras.size(), 3u);
  for (const bench::SphereResult& r : run.results) {
    EXPECT_EQ(r.dataset, "tiny");
    EXPECT_EQ(r.layout, ParticleLayout::Aos);
    EXPECT_EQ(r.bytesPerParticle, 16u);
    SphereSettings settings;
    settings.method = r.method;
    settings.billboard = r.billboard;
    settings.conservative = r.conservative;
    std::string why;
    if (SphereRenderer::supports(*context, settings, &why)) {
      EXPECT_TRUE(r.ok()) << r.reason;
      ASSERT_EQ(r.cameraMs.size(), 3u);
      EXPECT_GT(r.medianMs, 0.0);
      EXPECT_LE(r.minMs, r.medianMs);
      EXPECT_GE(r.maxMs, r.medianMs);
      EXPECT_GT(r.copyFraction, 0.0);
      EXPECT_EQ(r.frames, 1u);
    } else {
      EXPECT_EQ(r.status, "unsupported");
      EXPECT_EQ(r.reason, why);
    }
  }

  bench::ReportInfo info{"tiny-spheres", "tiny spheres", "pointrast bench x", "2024-01-01T00:00:00Z"};
  std::string md = bench::sphereMarkdownReport(run, info);
  EXPECT_NE(md.find("## short orbit: median GPU time per frame, ms"), std::string::npos) << md;
  EXPECT_NE(md.find("## long orbit: median GPU time per frame, ms"), std::string::npos) << md;
  EXPECT_NE(md.find("| data set | layout | method | screen | screen, conservative | camera | camera, "
                    "conservative |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| tiny (particles-drops, 3k) | aos | sphere-compute | "), std::string::npos) << md;
  EXPECT_NE(md.find("| tiny (particles-drops, 3k) | aos | sphere-strip | "), std::string::npos) << md;
  EXPECT_NE(md.find("## sphere-compute against the fastest other method"), std::string::npos) << md;
  EXPECT_NE(md.find("layout xyz skipped"), std::string::npos) << md;
  EXPECT_NE(md.find("**skipped**, it does not fit"), std::string::npos) << md;
  nlohmann::json j = bench::sphereRunJson(run, info);
  EXPECT_EQ(j["results"].size(), run.results.size());
  EXPECT_EQ(j["datasets"][1]["cameras"]["long"].size(), 3u);
  EXPECT_EQ(j["results"][0]["billboard"], "none") << "sphere-compute draws no billboards";
  EXPECT_EQ(j["results"][0]["camera_ms"].size(), 3u);
  std::string svg = bench::sphereSvgChart(run, info);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  size_t bars = 0;
  for (size_t at = svg.find("<title>"); at != std::string::npos; at = svg.find("<title>", at + 1))
    ++bars;
  EXPECT_EQ(bars, 4u) << "two orbits x two methods";
}

} // namespace

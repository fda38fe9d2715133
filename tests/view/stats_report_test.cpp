// The viewer's statistics report on a made-up session: no GPU or window needed.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "base/build_info.h"
#include "view/flight.h"
#include "view/stats_report.h"

namespace {

using namespace pointrast;

view::FrameLog madeUpLog() {
  view::FrameLog log;
  log.device.name = "Made-up GPU 9000";
  log.device.typeName = "discrete GPU";
  log.deviceLocalBytes = 1ull << 34;
  log.seconds = 12.5;
  // 20 frames: render 1..20 ms, present 0.5 ms, host 2 ms more than the passes; the last two in a larger
  // window with another method.
  for (int i = 1; i <= 20; ++i)
    log.add({double(i), 0.5, double(i) + 2.5}, i <= 18 ? "atomicmin" : "earlyz",
            i <= 18 ? view::Viewport{1280, 720} : view::Viewport{640, 480});
  log.add({3, 0.5, 5.5}, "atomicmin", {1280, 720}); // back to the first: listed once
  return log;
}

TEST(ViewStatsReport, MedianAndTailOfEveryPassAndOfTheFrame) {
  report::ReportInfo info{"view-test", "pointrast view: terrain", "pointrast view terrain --stats x.json",
                          "2026-01-01T00:00:00Z"};
  nlohmann::json j = view::viewStatsJson(madeUpLog(), {"terrain", 1'000'000, false, true}, info);
  EXPECT_EQ(j["name"], "view-test");
  EXPECT_EQ(j["commit"], buildCommit());
  EXPECT_EQ(j["device"]["name"], "Made-up GPU 9000");
  EXPECT_EQ(j["device"]["device_local_bytes"], 1ull << 34);
  EXPECT_DOUBLE_EQ(j["wall_seconds"].get<double>(), 12.5);
  EXPECT_EQ(j["frames"], 21);
  EXPECT_EQ(j["points"], 1'000'000);
  EXPECT_EQ(j["vsync"], false);
  EXPECT_EQ(j["clocks_settled"], false); // a viewer renders on demand: nothing settles its clocks
  EXPECT_EQ(j["methods"], nlohmann::json({"atomicmin", "earlyz"}));
  EXPECT_EQ(j["sizes"], nlohmann::json({"1280x720", "640x480"}));
  // Render times 1..20 and 3: sorted, the 11th of 21 is 10 (nearest rank), the 20th (ceil 0.95 * 21) is 19.
  const nlohmann::json& render = j["passes"]["render"];
  EXPECT_DOUBLE_EQ(render["median_ms"].get<double>(), 10);
  EXPECT_DOUBLE_EQ(render["p95_ms"].get<double>(), 19);
  EXPECT_DOUBLE_EQ(render["min_ms"].get<double>(), 1);
  EXPECT_DOUBLE_EQ(render["max_ms"].get<double>(), 20);
  EXPECT_DOUBLE_EQ(j["passes"]["present"]["median_ms"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["frame"]["gpu"]["median_ms"].get<double>(), 10.5);
  EXPECT_DOUBLE_EQ(j["frame"]["gpu"]["p95_ms"].get<double>(), 19.5);
  EXPECT_DOUBLE_EQ(j["frame"]["host"]["median_ms"].get<double>(), 12.5);
  EXPECT_TRUE(j["timing"].is_string());
}

TEST(ViewStatsReport, NoFramesGiveZerosNotNonsense) {
  nlohmann::json j = view::viewStatsJson(view::FrameLog{}, {"terrain", 1, true, true}, {});
  EXPECT_EQ(j["frames"], 0);
  EXPECT_EQ(j["passes"]["render"]["median_ms"].get<double>(), 0);
  EXPECT_EQ(j["frame"]["host"]["p95_ms"].get<double>(), 0);
  EXPECT_TRUE(j["methods"].is_array());
}

TEST(ViewStatsReport, AFlightsFiguresComeUnderFlight) {
  view::Flight flight({1, 120});
  flight.frameShown(0.5, true);
  nlohmann::json j = view::viewStatsJson(madeUpLog(), {"oct", 1, false, false}, {}, &flight);
  ASSERT_TRUE(j.contains("flight"));
  EXPECT_EQ(j["flight"], flight.result());
  EXPECT_FALSE(j["flight"]["complete"].get<bool>());
  EXPECT_FALSE(view::viewStatsJson(madeUpLog(), {"oct", 1, false, false}, {}).contains("flight"));
}

} // namespace

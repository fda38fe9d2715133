#include "view/stats_report.h"

#include <functional>
#include <vector>

#include "report/run_json.h"
#include "view/flight.h"

namespace pointrast::view {

namespace {

// Median and tail of one quantity over every frame; nearest-rank percentiles, so each figure is a frame's.
nlohmann::json msJson(const std::vector<FrameTiming>& frames,
                      const std::function<double(const FrameTiming&)>& value) {
  std::vector<double> ms;
  ms.reserve(frames.size());
  for (const FrameTiming& f : frames)
    ms.push_back(value(f));
  return {{"median_ms", report::percentile(ms, 0.5)},
          {"p95_ms", report::percentile(ms, 0.95)},
          {"min_ms", report::percentile(ms, 0.0)},
          {"max_ms", report::percentile(ms, 1.0)}};
}

} // namespace

nlohmann::json viewStatsJson(const FrameLog& log, const ViewSession& session, const report::ReportInfo& info,
                             const Flight* flight) {
  nlohmann::json j = report::identityJson(info, log.device, log.deviceLocalBytes, log.seconds);
  j["input"] = session.input;
  j["points"] = session.points;
  j["vsync"] = session.vsync;
  j["panel"] = session.panel;
  j["methods"] = log.methods;
  nlohmann::json sizes = nlohmann::json::array();
  for (const Viewport& v : log.sizes)
    sizes.push_back(std::to_string(v.width) + "x" + std::to_string(v.height));
  j["sizes"] = sizes;
  j["frames"] = log.frames.size();
  j["timing"] = "every frame the viewer rendered (input, a changed setting or a resize made it render); each "
                "pass's GPU time from timestamp queries; frame.gpu is the sum of the passes, frame.host the "
                "wall clock from the start of the render to the image handed to the display (the passes "
                "run one after the other and are waited for, so frame.gpu <= frame.host; the first frame's "
                "host time includes uploading the cloud); percentiles by nearest rank";
  // A viewer renders when something changes, not steadily, so the GPU's clocks rise and fall between its
  // frames; unlike `render` and `bench`, nothing settles them first, and the figures say so.
  j["clocks_settled"] = false;
  j["clocks"] = "not settled: frames are rendered on demand, so the GPU may run some of them at lowered "
                "clocks; `pointrast render` and `pointrast bench` settle the clocks before timing";
  const auto& f = log.frames;
  j["passes"]["render"] = msJson(f, [](const FrameTiming& t) { return t.renderMs; });
  j["passes"]["render"]["what"] = "clear + draw + resolve of the points";
  j["passes"]["present"] = msJson(f, [](const FrameTiming& t) { return t.presentMs; });
  j["passes"]["present"]["what"] = "the image copied into the swapchain image, and the panel when shown";
  j["frame"]["gpu"] = msJson(f, [](const FrameTiming& t) { return t.renderMs + t.presentMs; });
  j["frame"]["host"] = msJson(f, [](const FrameTiming& t) { return t.hostMs; });
  if (flight) j["flight"] = flight->result();
  return j;
}

} // namespace pointrast::view

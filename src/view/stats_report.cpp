#include "bench/view_report.h"

#include <functional>
#include <vector>

#include "bench/lod_report.h"
#include "bench/report_parts.h"

namespace pointrast::bench {

namespace {

// Median and tail of one quantity over every frame; nearest-rank percentiles, so each figure is a frame's.
nlohmann::json msJson(const std::vector<view::FrameTiming>& frames,
                      const std::function<double(const view::FrameTiming&)>& value) {
  std::vector<double> ms;
  ms.reserve(frames.size());
  for (const view::FrameTiming& f : frames)
    ms.push_back(value(f));
  return {{"median_ms", percentile(ms, 0.5)},
          {"p95_ms", percentile(ms, 0.95)},
          {"min_ms", percentile(ms, 0.0)},
          {"max_ms", percentile(ms, 1.0)}};
}

} // namespace

nlohmann::json viewStatsJson(const view::FrameLog& log, const ViewSession& session, const ReportInfo& info) {
  nlohmann::json j = identityJson(info, log.device, log.deviceLocalBytes, log.seconds);
  j["input"] = session.input;
  j["points"] = session.points;
  j["vsync"] = session.vsync;
  j["panel"] = session.panel;
  j["methods"] = log.methods;
  nlohmann::json sizes = nlohmann::json::array();
  for (const view::Viewport& v : log.sizes)
    sizes.push_back(std::to_string(v.width) + "x" + std::to_string(v.height));
  j["sizes"] = sizes;
  j["frames"] = log.frames.size();
  j["timing"] = "every frame the viewer rendered (input, a changed setting or a resize made it render); each "
                "pass's GPU time from timestamp queries; frame.gpu is the sum of the passes, frame.host the "
                "wall clock from the start of the render to the image handed to the display (the passes "
                "run one after the other and are waited for, so frame.gpu <= frame.host; the first frame's "
                "host time includes uploading the cloud); percentiles by nearest rank";
  const auto& f = log.frames;
  j["passes"]["render"] = msJson(f, [](const view::FrameTiming& t) { return t.renderMs; });
  j["passes"]["render"]["what"] = "clear + draw + resolve of the points";
  j["passes"]["present"] = msJson(f, [](const view::FrameTiming& t) { return t.presentMs; });
  j["passes"]["present"]["what"] = "the image copied into the swapchain image, and the panel when shown";
  j["frame"]["gpu"] = msJson(f, [](const view::FrameTiming& t) { return t.renderMs + t.presentMs; });
  j["frame"]["host"] = msJson(f, [](const view::FrameTiming& t) { return t.hostMs; });
  return j;
}

} // namespace pointrast::bench

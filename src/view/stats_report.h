// The viewer's statistics, written when it closes (`pointrast view --stats`): the GPU time of each pass and
// of the whole frame, and the host's frame time, as median and 95th percentile over every frame the
// session rendered, with the run's identity and device like every report.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "report/run_json.h"
#include "view/frame_log.h"

namespace pointrast::view {

// What the session showed, beside its frames.
struct ViewSession {
  std::string input; // the file or scene
  uint64_t points = 0;
  bool vsync = true;
  bool panel = true; // the panel was shown at the start (its drawing is part of the present pass)
};

class Flight;

// With a flight (`view --flight`), its figures (Flight::result) under "flight".
nlohmann::json viewStatsJson(const FrameLog& log, const ViewSession& session, const report::ReportInfo& info,
                             const Flight* flight = nullptr);

} // namespace pointrast::view

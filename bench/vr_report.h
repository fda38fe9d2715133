// The vr2022 suite's reports (bench/vr_suite.h): the run as JSON, a Markdown report (per view and
// configuration the stereo pass against two mono renders, with the targets: the VR frame within 4 ms, the
// stereo pass at least 1.5x faster than two mono renders) and an SVG chart of the two.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "bench/report.h"
#include "bench/vr_suite.h"

namespace pointrast::bench {

// The targets the report checks (the 2022 paper met 90 fps, 11.1 ms, with 8.3 ms of GPU time on an RTX 3090).
constexpr double kVrFrameTargetMs = 4.0;
constexpr double kStereoSpeedupTarget = 1.5;

nlohmann::json vrSuiteJson(const VrSuiteRun& run, const ReportInfo& info);
std::string vrSuiteMarkdown(const VrSuiteRun& run, const ReportInfo& info);
std::string vrSuiteSvg(const VrSuiteRun& run, const ReportInfo& info);
WrittenFiles writeVrSuiteReports(const VrSuiteRun& run, const ReportInfo& info,
                                 const std::filesystem::path& dir);

} // namespace pointrast::bench

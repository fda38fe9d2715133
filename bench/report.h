// Report writers for a BenchRun: one JSON document with everything (results, device, copy bandwidth,
// command line, date), a Markdown table laid out like Table 1 of the 2021 paper (rows: data set x
// order, columns: methods, one table per view) and an SVG bar chart written by hand (no plotting
// library: the binary stays one self-contained file).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "bench/runner.h"
#include "bench/sphere_runner.h"
#include "report/run_json.h"
#include "report/stats_json.h"

namespace pointrast::bench {

// Shared with every JSON a run writes (src/report), named here as the bench has always named them.
using report::batchStatsJson;
using report::formatMs;
using report::ReportInfo;
using report::sanitizeName;
using report::utcNow;

// One result as a flat object (also the line `pointrast bench --json` prints per result).
nlohmann::json resultJson(const BenchRun& run, const Result& result);
nlohmann::json runJson(const BenchRun& run, const ReportInfo& info);
std::string markdownReport(const BenchRun& run, const ReportInfo& info);
// Grouped bars of median ms per method for each data set, for the Morton order and the overview view
// (or the first order/view measured when those were not); log scale when values span more than 20x.
std::string svgChart(const BenchRun& run, const ReportInfo& info);

struct WrittenFiles {
  std::filesystem::path json, markdown, svg;
};
// Creates `dir` and writes the three files, each through a ".partial" file renamed into place, so an
// interrupted run leaves no half-written report. Throws InputError when a file cannot be written.
WrittenFiles writeReports(const BenchRun& run, const ReportInfo& info, const std::filesystem::path& dir);

// The sphere suite's reports (spheres2023), from the same machinery: one result as a flat object (also the
// line `pointrast bench --json` prints per result), the whole run, a Markdown report with one table per
// orbit (rows: data set x layout x method, columns: billboard x conservative), sphere-compute against the
// fastest rasterization pipeline and the per-frame counters, and an SVG chart of each method's fastest
// setting per data set and orbit.
nlohmann::json sphereResultJson(const SphereBenchRun& run, const SphereResult& result);
nlohmann::json sphereRunJson(const SphereBenchRun& run, const ReportInfo& info);
std::string sphereMarkdownReport(const SphereBenchRun& run, const ReportInfo& info);
std::string sphereSvgChart(const SphereBenchRun& run, const ReportInfo& info);
WrittenFiles writeSphereReports(const SphereBenchRun& run, const ReportInfo& info,
                                const std::filesystem::path& dir);

} // namespace pointrast::bench

// The parts every report writer shares (the point suites', the sphere suite's, the lod suite's): atomic
// files, the JSON header of a run, the Markdown header and footer, the data set list and the bar chart.
#pragma once

#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/report.h"

namespace pointrast::bench {

using report::identityJson;
using report::jsonFileText;
using report::vulkanVersionText;
using report::writeAtomically;

// The data sets that were measured (not skipped), in run order.
std::vector<const DatasetOutcome*> measuredDatasets(const std::vector<DatasetOutcome>& datasets);
// Table cells must not break the row: '|' is escaped, newlines flattened.
std::string mdCell(std::string_view text);

// What every report's JSON starts with: the run's identity, the device and the copy bandwidth.
nlohmann::json runHeaderJson(const ReportInfo& info, const gpu::DeviceInfo& device, uint64_t deviceLocalBytes,
                             const gpu::CopyBandwidth& copy, double seconds);
nlohmann::json datasetJson(const DatasetOutcome& d);

// The Markdown report's first lines: title, device, copy bandwidth, and an early stop.
void markdownHeader(std::ostringstream& md, const ReportInfo& info, const gpu::DeviceInfo& device,
                    uint64_t deviceLocalBytes, const gpu::CopyBandwidth& copy, const std::string& stopped);
// The lines after the run's own settings: how to read the figures, when and how the run was made.
void markdownFooter(std::ostringstream& md, const ReportInfo& info, double seconds);
void markdownDatasets(std::ostringstream& md, const std::vector<DatasetOutcome>& datasets);
void markdownNotMeasured(std::ostringstream& md, const std::set<std::string>& reasons);

// A grouped bar chart of milliseconds: one group per x label, one bar per series (colored as in the
// legend); log scale when values span more than 20x.
struct BarChart {
  std::string title;               // "<title>: median GPU ms per frame (lower is better)" is drawn from it
  std::string subtitle;            // device, image, what the bars show
  std::vector<std::string> groups; // labels; " (" starts a second line
  std::vector<std::string> series;
  // values[group][series]: milliseconds; kNoBar draws nothing, kNotMeasured "n/a".
  std::vector<std::vector<double>> values;
};
constexpr double kNoBar = -1, kNotMeasured = -2;
std::string svgBars(const BarChart& chart);

// Writes the three files of a report through ".partial" files renamed into place; everything is rendered
// by the caller before the first file is written, so a failure leaves no mixed set.
WrittenFiles writeReportFiles(const std::filesystem::path& dir, const std::string& name,
                              const std::string& json, const std::string& markdown, const std::string& svg);

} // namespace pointrast::bench

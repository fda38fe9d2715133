// What every JSON a run writes shares, whoever writes it (`render --json`, `view --stats`, the bench
// reports): the run's identity and device, indented JSON that survives text that is not UTF-8, files
// written whole or not at all, and the small formatters of names, dates and milliseconds.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "gpu/context.h"

namespace pointrast::report {

struct ReportInfo {
  std::string name;        // file stem: <name>.json, <name>.md, <name>.svg
  std::string title;       // "paper2021 (scale 0.001)", "terrain-20k"
  std::string commandLine; // as typed, to reproduce the run
  std::string date;        // ISO 8601, UTC
};

// The run's identity (name, title, command line, date, commit, wall seconds) and the device: the start of
// every report's JSON, also of reports that measure no copy bandwidth (the viewer's statistics).
nlohmann::json identityJson(const ReportInfo& info, const gpu::DeviceInfo& device, uint64_t deviceLocalBytes,
                            double seconds);

// Writes `content` through a ".partial" file renamed into place. Throws InputError naming the file.
void writeAtomically(const std::filesystem::path& path, const std::string& content);

// A report's JSON, indented; text that is not UTF-8 (a file name in another encoding) is replaced rather
// than failing the report of a finished run.
std::string jsonFileText(const nlohmann::json& j);

// "NVIDIA H200" -> "nvidia-h200": lower case, runs of anything but letters and digits become one '-'.
std::string sanitizeName(std::string_view text);
// Median milliseconds with three significant digits and no exponent: 1234, 12.3, 1.23, 0.123, 0.0123.
std::string formatMs(double ms);
// A Vulkan API version as 1.3.277.
std::string vulkanVersionText(uint32_t version);
// Now, as 2024-05-01T12:34:56Z.
std::string utcNow();
// Percentile p (0..1) of values, nearest rank (each figure is one of the values); 0 for none.
double percentile(std::vector<double> values, double p);

} // namespace pointrast::report

// The parts every report writer shares (bench/report_parts.h).
#include "bench/report_parts.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>

#include "base/build_info.h"
#include "base/error.h"
#include "bench/suites.h"

namespace pointrast::bench {

namespace {

std::string xmlEscape(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
    case '&':
      out += "&amp;";
      break;
    case '<':
      out += "&lt;";
      break;
    case '>':
      out += "&gt;";
      break;
    case '"':
      out += "&quot;";
      break;
    default:
      out += c;
    }
  }
  return out;
}

} // namespace

std::vector<const DatasetOutcome*> measuredDatasets(const std::vector<DatasetOutcome>& datasets) {
  std::vector<const DatasetOutcome*> out;
  for (const DatasetOutcome& d : datasets)
    if (!d.skipped) out.push_back(&d);
  return out;
}

// Table cells must not break the row: '|' is escaped, newlines flattened.
std::string mdCell(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out;
}

// What every report's JSON starts with: the run's identity, the device and the copy bandwidth.
nlohmann::json runHeaderJson(const ReportInfo& info, const gpu::DeviceInfo& device, uint64_t deviceLocalBytes,
                             const gpu::CopyBandwidth& copy, double seconds) {
  nlohmann::json j = identityJson(info, device, deviceLocalBytes, seconds);
  j["copy_bandwidth"] = {
      {"bytes", copy.bytes},
      {"repeats", copy.repeats},
      {"median_ms", copy.medianMs},
      {"gb_per_s", copy.bytesPerSecond * 1e-9},
      {"transfer_gb_per_s", copy.transferBytesPerSecond * 1e-9},
      {"shader_gb_per_s", copy.shaderBytesPerSecond * 1e-9},
      {"note",
       "the faster of vkCmdCopyBuffer (transfer_gb_per_s) and a compute-shader copy of 16 B per "
       "invocation (shader_gb_per_s) between two device buffers; counts bytes read + bytes written per "
       "second, since a copy moves every byte through memory twice"}};
  return j;
}

nlohmann::json datasetJson(const DatasetOutcome& d) {
  nlohmann::json dj;
  dj["name"] = d.dataset.name;
  dj["label"] = d.dataset.label;
  dj["source"] = d.dataset.source;
  dj["description"] = d.description;
  dj["points"] = d.points;
  dj["status"] = d.skipped ? "skipped" : "ok";
  if (d.skipped) dj["reason"] = d.reason;
  dj["gpu_bytes_estimate"] = d.memory.gpuBytes;
  dj["host_bytes_estimate"] = d.memory.hostBytes;
  return dj;
}

// The Markdown report's first lines: title, device, copy bandwidth, and an early stop.
void markdownHeader(std::ostringstream& md, const ReportInfo& info, const gpu::DeviceInfo& device,
                    uint64_t deviceLocalBytes, const gpu::CopyBandwidth& copy, const std::string& stopped) {
  md << "# pointrast bench: " << info.title << "\n\n";
  md << "- Device: **" << device.name << "** (" << device.typeName << ", driver " << device.driver
     << ", Vulkan " << vulkanVersionText(device.apiVersion) << "), " << bytesText(deviceLocalBytes)
     << " of device-local memory\n";
  md << "- Copy bandwidth: **" << printf1("%.1f", copy.bytesPerSecond * 1e-9)
     << " GB/s**, measured in this run: the faster of vkCmdCopyBuffer ("
     << printf1("%.1f", copy.transferBytesPerSecond * 1e-9) << " GB/s) and a compute-shader copy of 16 B per "
     << "invocation (" << printf1("%.1f", copy.shaderBytesPerSecond * 1e-9) << " GB/s), "
     << bytesText(copy.bytes) << " between two device buffers, median of " << copy.repeats
     << ". It counts bytes read + bytes written per second (a copy moves every byte through memory twice): "
        "the rate at which a method that only reads its points could at most stream them.\n";
  if (!stopped.empty()) md << "- **Stopped early**: " << stopped << ".\n";
}

// The lines after the run's own settings: how to read the figures, when and how the run was made.
void markdownFooter(std::ostringstream& md, const ReportInfo& info, double seconds) {
  md << "- Ratios between methods of one run are the figures that count; absolute times depend on clocks "
        "and drivers.\n";
  md << "- Date: " << info.date << "; the run took " << printf1("%.0f", seconds)
     << " s (wall clock); pointrast " << buildCommit() << ".\n";
  md << "- Command: `" << info.commandLine << "`\n\n";
}

void markdownDatasets(std::ostringstream& md, const std::vector<DatasetOutcome>& datasets) {
  md << "## Data sets\n\n";
  for (const DatasetOutcome& d : datasets) {
    md << "- " << d.dataset.label << ": ";
    if (d.skipped)
      md << "**skipped**, " << d.reason << "\n";
    else {
      md << (d.description.empty() ? d.dataset.source : d.description);
      // Streamed data sets (an octree through the node cache) have no upload to estimate.
      if (d.memory.gpuHave > 0) md << "; " << d.memory.describe();
      md << "\n";
    }
  }
}

void markdownNotMeasured(std::ostringstream& md, const std::set<std::string>& reasons) {
  if (reasons.empty()) return;
  md << "\n## Not measured (n/a)\n\n";
  for (const std::string& why : reasons)
    md << "- " << why << "\n";
}

namespace {

// The value axis of a bar chart: its range and ticks, powers of ten on a log axis (when values span more
// than 20x), a 1-2-5 step on a linear one.
struct ChartAxis {
  bool any = false; // a value to draw
  bool logScale = false;
  double lo = 0, hi = 1;
  std::vector<double> ticks;
};

ChartAxis chartAxis(const BarChart& chart) {
  ChartAxis axis;
  double lo = INFINITY, hi = 0;
  for (const auto& group : chart.values)
    for (double v : group)
      if (v > 0) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
  axis.any = hi > 0;
  axis.logScale = axis.any && hi / lo > 20;
  if (axis.logScale) {
    axis.lo = std::pow(10.0, std::floor(std::log10(lo)));
    axis.hi = std::pow(10.0, std::ceil(std::log10(hi)));
    if (axis.hi <= axis.lo) axis.hi = axis.lo * 10;
    // 1-2-5 steps when the axis spans few decades, else one tick per decade.
    const bool fine = axis.hi / axis.lo <= 1000.0001;
    for (double decade = axis.lo; decade <= axis.hi * 1.0001; decade *= 10)
      for (double m : {1.0, 2.0, 5.0})
        if ((m == 1.0 || fine) && decade * m <= axis.hi * 1.0001) axis.ticks.push_back(decade * m);
  } else if (axis.any) {
    double raw = hi / 5, magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    double step = magnitude;
    for (double m : {1.0, 2.0, 5.0, 10.0})
      if (m * magnitude >= raw) {
        step = m * magnitude;
        break;
      }
    axis.hi = std::ceil(hi / step) * step;
    for (double t = 0; t <= axis.hi * 1.0001; t += step)
      axis.ticks.push_back(t);
  }
  return axis;
}

} // namespace

std::string svgBars(const BarChart& chart) {
  const ChartAxis axis = chartAxis(chart);
  const bool any = axis.any, logScale = axis.logScale;
  const double axisLo = axis.lo, axisHi = axis.hi;
  const std::vector<double>& ticks = axis.ticks;

  const double width = 1000, height = 560, left = 80, right = 190, top = 60, bottom = 90;
  const double plotW = width - left - right, plotH = height - top - bottom;
  auto y = [&](double v) {
    double t = logScale ? (std::log10(v) - std::log10(axisLo)) / (std::log10(axisHi) - std::log10(axisLo))
                        : (v - axisLo) / (axisHi - axisLo);
    return top + plotH * (1 - std::clamp(t, 0.0, 1.0));
  };
  // Colors that stay apart for up to twelve series (then they repeat).
  static const char* kPalette[] = {"#4e79a7", "#f28e2b", "#e15759", "#76b7b2", "#59a14f", "#edc948",
                                   "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac", "#1f77b4", "#17becf"};
  auto num = [](double v) { return printf1("%.1f", v); };

  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" viewBox=\"0 0 " << width << " " << height << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s << "<text x=\"" << left << "\" y=\"24\" font-size=\"16\">" << xmlEscape(chart.title)
    << ": median GPU ms per frame (lower is better)</text>\n";
  s << "<text x=\"" << left << "\" y=\"44\" fill=\"#555\">" << xmlEscape(chart.subtitle)
    << (logScale ? ", log scale" : "") << "</text>\n";
  for (double t : ticks) {
    s << "<line x1=\"" << left << "\" x2=\"" << left + plotW << "\" y1=\"" << num(y(t)) << "\" y2=\""
      << num(y(t)) << "\" stroke=\"#ddd\"/>\n";
    s << "<text x=\"" << left - 6 << "\" y=\"" << num(y(t) + 4) << "\" text-anchor=\"end\">"
      << printf1("%g", t) << "</text>\n";
  }
  s << "<text transform=\"translate(18," << num(top + plotH / 2) << ") rotate(-90)\" text-anchor=\"middle\">"
    << "ms</text>\n";
  s << "<line x1=\"" << left << "\" x2=\"" << left + plotW << "\" y1=\"" << top + plotH << "\" y2=\""
    << top + plotH << "\" stroke=\"black\"/>\n";

  const size_t groups = std::max<size_t>(1, chart.groups.size()),
               bars = std::max<size_t>(1, chart.series.size());
  const double groupW = plotW / double(groups), barW = groupW * 0.8 / double(bars);
  for (size_t g = 0; g < chart.groups.size(); ++g) {
    const double x0 = left + g * groupW + groupW * 0.1;
    for (size_t b = 0; b < chart.series.size(); ++b) {
      const double v = chart.values[g][b];
      const double x = x0 + b * barW;
      if (v > 0) {
        const double yTop = y(v);
        s << "<rect x=\"" << num(x) << "\" y=\"" << num(yTop) << "\" width=\"" << num(barW * 0.9)
          << "\" height=\"" << num(top + plotH - yTop) << "\" fill=\"" << kPalette[b % std::size(kPalette)]
          << "\"><title>" << xmlEscape(chart.series[b]) << ": " << formatMs(v) << " ms</title></rect>\n";
      } else if (v == kNotMeasured) {
        s << "<text x=\"" << num(x + barW * 0.45) << "\" y=\"" << num(top + plotH - 4)
          << "\" font-size=\"8\" text-anchor=\"middle\" fill=\"#999\">n/a</text>\n";
      }
    }
    // The label's "(generator, size)" goes on a second line so long names do not run into each other.
    const std::string& label = chart.groups[g];
    const size_t paren = label.find(" (");
    const double cx = left + (g + 0.5) * groupW;
    s << "<text x=\"" << num(cx) << "\" y=\"" << top + plotH + 20 << "\" text-anchor=\"middle\">"
      << xmlEscape(label.substr(0, paren)) << "</text>\n";
    if (paren != std::string::npos)
      s << "<text x=\"" << num(cx) << "\" y=\"" << top + plotH + 36
        << "\" text-anchor=\"middle\" fill=\"#555\">" << xmlEscape(label.substr(paren + 1)) << "</text>\n";
  }
  if (!any)
    s << "<text x=\"" << left + plotW / 2 << "\" y=\"" << top + plotH / 2
      << "\" text-anchor=\"middle\" fill=\"#999\">no measurements</text>\n";
  for (size_t b = 0; b < chart.series.size(); ++b) {
    const double ly = top + 10 + b * 20.0;
    s << "<rect x=\"" << left + plotW + 20 << "\" y=\"" << ly - 10 << "\" width=\"12\" height=\"12\" fill=\""
      << kPalette[b % std::size(kPalette)] << "\"/>\n";
    s << "<text x=\"" << left + plotW + 38 << "\" y=\"" << ly << "\">" << xmlEscape(chart.series[b])
      << "</text>\n";
  }
  s << "</svg>\n";
  return s.str();
}

WrittenFiles writeReportFiles(const std::filesystem::path& dir, const std::string& name,
                              const std::string& json, const std::string& markdown, const std::string& svg) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError(dir.string() + ": cannot create the output folder");
  WrittenFiles files{dir / (name + ".json"), dir / (name + ".md"), dir / (name + ".svg")};
  writeAtomically(files.json, json);
  writeAtomically(files.markdown, markdown);
  writeAtomically(files.svg, svg);
  return files;
}

} // namespace pointrast::bench

#include "bench/report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "base/build_info.h"
#include "base/error.h"
#include "bench/lod_report.h"
#include "bench/report_parts.h"
#include "bench/suites.h"

namespace pointrast::bench {

namespace {

std::string apiVersion(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

// Results by (data set, order, view, method), for the table cells.
class ResultIndex {
public:
  explicit ResultIndex(const BenchRun& run) {
    for (const Result& r : run.results)
      map_[{r.dataset, int(r.order), int(r.view), r.method.index()}] = &r;
  }
  const Result* find(const std::string& dataset, Order order, View view, Method method) const {
    auto it = map_.find({dataset, int(order), int(view), method.index()});
    return it == map_.end() ? nullptr : it->second;
  }

private:
  std::map<std::tuple<std::string, int, int, uint32_t>, const Result*> map_;
};

std::vector<const DatasetOutcome*> measuredDatasets(const std::vector<DatasetOutcome>& datasets) {
  std::vector<const DatasetOutcome*> out;
  for (const DatasetOutcome& d : datasets)
    if (!d.skipped) out.push_back(&d);
  return out;
}

// The order and view the chart and the bandwidth table show: Morton / overview when measured.
Order chartOrder(const BenchConfig& c) {
  bool morton = std::find(c.orders.begin(), c.orders.end(), Order::Morton) != c.orders.end();
  return morton || c.orders.empty() ? Order::Morton : c.orders.front();
}
View mainView(const BenchConfig& c) {
  bool overview = std::find(c.views.begin(), c.views.end(), View::Overview) != c.views.end();
  return overview || c.views.empty() ? View::Overview : c.views.front();
}

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

} // namespace

// The parts every report writer shares (bench/report_parts.h).

void writeAtomically(const std::filesystem::path& path, const std::string& content) {
  std::filesystem::path partial = path;
  partial += ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out << content;
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(partial, ec);
      throw InputError(path.string() + ": cannot write the file");
    }
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::filesystem::remove(partial, ec);
    throw InputError(path.string() + ": cannot write the file");
  }
}

nlohmann::json identityJson(const ReportInfo& info, const gpu::DeviceInfo& device, uint64_t deviceLocalBytes,
                            double seconds) {
  nlohmann::json j;
  j["name"] = info.name;
  j["title"] = info.title;
  j["command_line"] = info.commandLine;
  j["date"] = info.date;
  j["commit"] = buildCommit();
  j["wall_seconds"] = seconds;
  j["device"] = {{"name", device.name},          {"type", device.typeName},
                 {"driver", device.driver},      {"vulkan", apiVersion(device.apiVersion)},
                 {"vendor_id", device.vendorId}, {"device_local_bytes", deviceLocalBytes}};
  return j;
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
     << ", Vulkan " << apiVersion(device.apiVersion) << "), " << bytesText(deviceLocalBytes)
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
    else
      md << (d.description.empty() ? d.dataset.source : d.description) << "; " << d.memory.describe() << "\n";
  }
}

void markdownNotMeasured(std::ostringstream& md, const std::set<std::string>& reasons) {
  if (reasons.empty()) return;
  md << "\n## Not measured (n/a)\n\n";
  for (const std::string& why : reasons)
    md << "- " << why << "\n";
}

std::string svgBars(const BarChart& chart) {
  double lo = INFINITY, hi = 0;
  for (const auto& group : chart.values)
    for (double v : group)
      if (v > 0) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
  const bool any = hi > 0;
  const bool logScale = any && hi / lo > 20;
  // Axis range and ticks: powers of ten on a log axis, a 1-2-5 step on a linear one.
  double axisLo = 0, axisHi = 1;
  std::vector<double> ticks;
  if (logScale) {
    axisLo = std::pow(10.0, std::floor(std::log10(lo)));
    axisHi = std::pow(10.0, std::ceil(std::log10(hi)));
    if (axisHi <= axisLo) axisHi = axisLo * 10;
    // 1-2-5 steps when the axis spans few decades, else one tick per decade.
    const bool fine = axisHi / axisLo <= 1000.0001;
    for (double decade = axisLo; decade <= axisHi * 1.0001; decade *= 10)
      for (double m : {1.0, 2.0, 5.0})
        if ((m == 1.0 || fine) && decade * m <= axisHi * 1.0001) ticks.push_back(decade * m);
  } else if (any) {
    double raw = hi / 5, magnitude = std::pow(10.0, std::floor(std::log10(raw)));
    double step = magnitude;
    for (double m : {1.0, 2.0, 5.0, 10.0})
      if (m * magnitude >= raw) {
        step = m * magnitude;
        break;
      }
    axisHi = std::ceil(hi / step) * step;
    for (double t = 0; t <= axisHi * 1.0001; t += step)
      ticks.push_back(t);
  }

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

std::string jsonFileText(const nlohmann::json& j) {
  return j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
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

std::string sanitizeName(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      out += char(std::tolower(static_cast<unsigned char>(c)));
    } else if (!out.empty() && out.back() != '-') {
      out += '-';
    }
  }
  while (!out.empty() && out.back() == '-')
    out.pop_back();
  return out.empty() ? "device" : out;
}

std::string formatMs(double ms) {
  if (!(ms > 0) || !std::isfinite(ms)) return "0";
  int decimals = std::clamp(2 - int(std::floor(std::log10(ms))), 0, 9);
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, ms);
  return text;
}

std::string utcNow() {
  std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

nlohmann::json batchStatsJson(const BatchStats& b) {
  return {{"batches_processed", b.batchesProcessed},
          {"batches_rendered", b.batchesRendered},
          {"points_processed", b.pointsProcessed},
          {"points_rendered", b.pointsRendered},
          {"points_blended", b.pointsBlended},
          {"blend_atomics", b.blendAtomics},
          {"points_by_words", {b.pointsByWords[0], b.pointsByWords[1], b.pointsByWords[2]}},
          {"bytes_read", b.bytesRead}};
}

nlohmann::json resultJson(const BenchRun& run, const Result& r) {
  nlohmann::json j;
  j["dataset"] = r.dataset;
  j["order"] = orderName(r.order);
  j["view"] = viewName(r.view);
  j["method"] = methodName(r.method);
  j["status"] = r.status;
  if (!r.reason.empty()) j["reason"] = r.reason;
  j["points"] = r.points;
  j["width"] = run.config.width;
  j["height"] = run.config.height;
  j["frames"] = r.stats.frames;
  j["warmup"] = run.warmup;
  j["median_ms"] = r.stats.medianMs;
  j["min_ms"] = r.stats.minMs;
  j["max_ms"] = r.stats.maxMs;
  j["points_per_second"] = r.pointsPerSecond;
  j["bytes_per_point"] = r.bytesPerPoint;
  j["effective_gb_per_s"] = r.effectiveBytesPerSecond * 1e-9;
  j["copy_gb_per_s"] = run.copy.bytesPerSecond * 1e-9;
  if (!run.stopped.empty()) j["stopped"] = run.stopped;
  j["copy_fraction"] = r.copyFraction;
  if (r.stats.batch) j["batch_stats"] = batchStatsJson(*r.stats.batch);
  if (r.stats.lod) j["lod_stats"] = lodStatsJson(*r.stats.lod);
  j["camera"] = r.camera;
  return j;
}

nlohmann::json runJson(const BenchRun& run, const ReportInfo& info) {
  nlohmann::json j = runHeaderJson(info, run.device, run.deviceLocalBytes, run.copy, run.seconds);
  nlohmann::json settings;
  settings["width"] = run.config.width;
  settings["height"] = run.config.height;
  settings["frames"] = run.config.frames;
  settings["warmup"] = run.warmup;
  settings["seconds_per_combination"] = run.config.secondsPerCombination;
  settings["fov"] = run.config.fovY;
  settings["order_seed"] = run.config.orderSeed;
  settings["timing"] =
      "GPU time of clear + render + resolve per frame from timestamp queries; median, min, max";
  for (Method m : run.config.methods)
    settings["methods"].push_back(methodName(m));
  for (Order o : run.config.orders)
    settings["orders"].push_back(orderName(o));
  for (View v : run.config.views)
    settings["views"].push_back(viewName(v));
  j["settings"] = settings;
  j["datasets"] = nlohmann::json::array();
  for (const DatasetOutcome& d : run.datasets)
    j["datasets"].push_back(datasetJson(d));
  j["results"] = nlohmann::json::array();
  for (const Result& r : run.results)
    j["results"].push_back(resultJson(run, r));
  if (!run.octrees.empty()) j["octrees"] = octreesJson(run.octrees);
  return j;
}

std::string markdownReport(const BenchRun& run, const ReportInfo& info) {
  const BenchConfig& c = run.config;
  const ResultIndex index(run);
  const auto datasets = measuredDatasets(run.datasets);
  std::ostringstream md;
  markdownHeader(md, info, run.device, run.deviceLocalBytes, run.copy, run.stopped);
  md << "- Image " << c.width << "x" << c.height << ", vertical field of view " << printf1("%g", c.fovY)
     << " degrees; each cell is the median GPU time of " << c.frames << " frames after " << run.warmup
     << " warm-up frames, a frame being clear + render + resolve, timed with timestamp queries. After each "
        "upload, frames of the first method are rendered until their time settles, so that GPU clocks that "
        "fell to idle during the host's work are up again.\n";
  {
    // Combinations the time budget shortened, grouped by method: "hw-points 12x (3-5 frames)".
    struct Shortened {
      size_t combinations = 0;
      uint32_t fewest = UINT32_MAX, most = 0; // frames
    };
    std::map<std::string, Shortened> shortened;
    for (const Result& r : run.results)
      if (r.ok() && r.stats.frames < c.frames) {
        Shortened& s = shortened[methodName(r.method)];
        ++s.combinations;
        s.fewest = std::min(s.fewest, r.stats.frames);
        s.most = std::max(s.most, r.stats.frames);
      }
    if (!shortened.empty()) {
      md << "- Time budget " << printf1("%g", c.secondsPerCombination)
         << " s per combination: slower combinations were timed over fewer frames after 1 warm-up frame "
            "(JSON `frames`):";
      for (const auto& [name, s] : shortened)
        md << " " << name << " " << s.combinations << "x (" << s.fewest
           << (s.most != s.fewest ? "-" + std::to_string(s.most) : "") << " frames);";
      md << "\n";
    }
  }
  markdownFooter(md, info, run.seconds);

  auto table = [&](View view, auto&& cell) {
    md << "| data set | order |";
    for (Method m : c.methods)
      md << " " << methodName(m) << " |";
    md << "\n| --- | --- |";
    for (size_t k = 0; k < c.methods.size(); ++k)
      md << " ---: |";
    md << "\n";
    for (const DatasetOutcome* d : datasets) {
      for (Order o : c.orders) {
        // A data set measured in fewer orders or views than the run (a suite's choice) has no row here.
        bool any = false;
        for (Method m : c.methods)
          any = any || index.find(d->dataset.name, o, view, m);
        if (!any) continue;
        md << "| " << mdCell(d->dataset.label) << " | " << orderName(o) << " |";
        for (Method m : c.methods) {
          const Result* r = index.find(d->dataset.name, o, view, m);
          md << " " << (!r ? "" : r->ok() ? cell(*r) : std::string("n/a")) << " |";
        }
        md << "\n";
      }
    }
    md << "\n";
  };

  for (View v : c.views) {
    md << "## " << viewName(v) << ": median GPU time per frame, ms\n\n";
    table(v, [](const Result& r) { return formatMs(r.stats.medianMs); });
  }

  const View bandwidthView = mainView(c);
  if (!c.views.empty()) {
    md << "## " << viewName(bandwidthView) << ": effective bandwidth, % of copy bandwidth\n\n";
    md << "Effective bandwidth = points x bytes of point data the method must read per point / median time. "
          "Bytes per point:";
    bool batched = false;
    for (size_t k = 0; k < c.methods.size(); ++k) {
      const MethodInfo& m = methodInfo(c.methods[k]);
      const bool counted = m.layout == SceneLayout::Batched || m.layout == SceneLayout::Octree;
      md << (k ? ", " : " ") << m.name << " " << (counted ? "*" : std::to_string(m.bytesPerPoint));
      batched = batched || counted;
    }
    md << ".";
    if (batched)
      md << " *: the bytes the frame read, from the batch statistics: 4 per coordinate word of each point "
            "processed, 32 per batch's (or octree node's) bounds; batch-hqs and lod-hqs read both twice "
            "(depth "
            "and blending pass) and the color of each blended point.";
    md << "\n\n";
    table(bandwidthView, [](const Result& r) { return printf1("%.0f%%", r.copyFraction * 100); });
  }

  // The 2022 paper's Table 2: what the batch methods processed and rendered, per frame.
  bool batchStats = false;
  for (const Result& r : run.results)
    batchStats = batchStats || (r.ok() && r.stats.batch && !r.stats.lod);
  if (batchStats) {
    md << "## Batch statistics per frame (the 2022 paper's Table 2)\n\n";
    md << "Batches of 10,240 points: processed (all), rendered (not culled); points processed (in rendered "
          "batches) and how many coordinate words they needed; points rendered (passed early-z and did the "
          "atomic); batch-hqs: points blended.\n\n";
    md << "| data set | order | view | method | batches | rendered | points processed | 1 / 2 / 3 words | "
          "points rendered | blended | ms |\n";
    md << "| --- | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    auto count = [](uint64_t n) { return shortCount(n); };
    for (const DatasetOutcome* d : datasets)
      for (Order o : c.orders)
        for (View v : c.views)
          for (Method m : c.methods) {
            const Result* r = index.find(d->dataset.name, o, v, m);
            if (!r || !r->ok() || !r->stats.batch || r->stats.lod) continue; // LOD rows: their own table
            const BatchStats& b = *r->stats.batch;
            auto share = [&](uint64_t n) {
              return b.pointsProcessed ? printf1("%.0f%%", 100.0 * double(n) / double(b.pointsProcessed))
                                       : std::string("-");
            };
            md << "| " << mdCell(d->dataset.label) << " | " << orderName(o) << " | " << viewName(v) << " | "
               << methodName(m) << " | " << b.batchesProcessed << " | " << b.batchesRendered << " | "
               << count(b.pointsProcessed) << " | " << share(b.pointsByWords[0]) << " / "
               << share(b.pointsByWords[1]) << " / " << share(b.pointsByWords[2]) << " | "
               << count(b.pointsRendered) << " | "
               << (m.info().output == MethodOutput::Blend ? count(b.pointsBlended) : "-") << " | "
               << formatMs(r->stats.medianMs) << " |\n";
          }
    md << "\n";
  }

  markdownLodStatistics(md, run);
  markdownDatasets(md, run.datasets);
  std::set<std::string> reasons;
  for (const Result& r : run.results)
    if (!r.ok()) reasons.insert(std::string(methodName(r.method)) + ": " + r.reason);
  markdownNotMeasured(md, reasons);
  return md.str();
}

std::string svgChart(const BenchRun& run, const ReportInfo& info) {
  const BenchConfig& c = run.config;
  const ResultIndex index(run);
  const auto datasets = measuredDatasets(run.datasets);
  const Order order = chartOrder(c);
  const View view = mainView(c);
  BarChart chart;
  chart.title = info.title;
  chart.subtitle = run.device.name + ", " + std::to_string(c.width) + "x" + std::to_string(c.height) + ", " +
                   orderName(order) + " order, " + viewName(view) + " view";
  for (Method m : c.methods)
    chart.series.push_back(methodName(m));
  for (const DatasetOutcome* d : datasets) {
    chart.groups.push_back(d->dataset.label);
    std::vector<double>& values = chart.values.emplace_back();
    for (Method m : c.methods) {
      const Result* r = index.find(d->dataset.name, order, view, m);
      values.push_back(!r ? kNoBar : r->ok() && r->stats.medianMs > 0 ? r->stats.medianMs : kNotMeasured);
    }
  }
  return svgBars(chart);
}

WrittenFiles writeReports(const BenchRun& run, const ReportInfo& info, const std::filesystem::path& dir) {
  return writeReportFiles(dir, info.name, jsonFileText(runJson(run, info)), markdownReport(run, info),
                          svgChart(run, info));
}

// ---- spheres2023 ----------------------------------------------------------------------------------------

namespace {

// "screen", "camera, conservative": a billboard setting, the columns of the sphere tables.
struct SphereVariant {
  SphereBillboard billboard;
  bool conservative;
  std::string name() const {
    return std::string(sphereBillboardName(billboard)) + (conservative ? ", conservative" : "");
  }
};

std::vector<SphereVariant> sphereVariants(const SphereBenchConfig& c) {
  std::vector<SphereVariant> variants;
  for (SphereBillboard b : c.billboards)
    for (bool conservative : c.conservative)
      variants.push_back({b, conservative});
  return variants;
}

// "sphere-strip, soa8, camera, conservative": what a result measured.
std::string sphereSetting(const SphereResult& r) {
  std::string text = std::string(sphereMethodName(r.method)) + ", " + particleLayoutName(r.layout);
  if (r.billboards()) text += ", " + SphereVariant{r.billboard, r.conservative}.name();
  return text;
}

// Sphere results by (data set, layout, orbit, method, billboard, conservative); a method without
// billboards is found under any billboard setting.
class SphereResultIndex {
public:
  explicit SphereResultIndex(const SphereBenchRun& run) {
    for (const SphereResult& r : run.results)
      map_[key(r.dataset, r.layout, r.orbit, r.method, r.billboard, r.conservative)] = &r;
  }
  const SphereResult* find(const std::string& dataset, ParticleLayout layout, Orbit orbit,
                           SphereMethod method, SphereBillboard billboard = SphereBillboard::Screen,
                           bool conservative = false) const {
    if (!sphereMethodTakesBillboards(method)) {
      billboard = SphereBillboard::Screen;
      conservative = false;
    }
    auto it = map_.find(key(dataset, layout, orbit, method, billboard, conservative));
    return it == map_.end() ? nullptr : it->second;
  }

private:
  using Key = std::tuple<std::string, int, int, int, int, bool>;
  static Key key(const std::string& dataset, ParticleLayout layout, Orbit orbit, SphereMethod method,
                 SphereBillboard billboard, bool conservative) {
    return {dataset, int(layout), int(orbit), int(method), int(billboard), conservative};
  }
  std::map<Key, const SphereResult*> map_;
};

// The fastest measured result among those `accept` takes, for one data set and orbit.
template <class Accept>
const SphereResult* fastest(const SphereBenchRun& run, const std::string& dataset, Orbit orbit,
                            Accept&& accept) {
  const SphereResult* best = nullptr;
  for (const SphereResult& r : run.results)
    if (r.dataset == dataset && r.orbit == orbit && r.ok() && r.medianMs > 0 && accept(r) &&
        (!best || r.medianMs < best->medianMs))
      best = &r;
  return best;
}

} // namespace

nlohmann::json sphereResultJson(const SphereBenchRun& run, const SphereResult& r) {
  nlohmann::json j;
  j["suite"] = "spheres";
  j["dataset"] = r.dataset;
  j["layout"] = particleLayoutName(r.layout);
  j["orbit"] = orbitName(r.orbit);
  j["method"] = sphereMethodName(r.method);
  j["billboard"] = r.billboards() ? sphereBillboardName(r.billboard) : "none";
  j["conservative"] = r.conservative;
  j["status"] = r.status;
  if (!r.reason.empty()) j["reason"] = r.reason;
  j["particles"] = r.particles;
  j["width"] = run.config.width;
  j["height"] = run.config.height;
  j["cameras"] = r.cameraMs.size();
  j["frames"] = r.frames;
  j["warmup"] = run.warmup;
  j["median_ms"] = r.medianMs;
  j["min_ms"] = r.minMs;
  j["max_ms"] = r.maxMs;
  j["camera_ms"] = r.cameraMs;
  j["particles_per_second"] = r.particlesPerSecond;
  j["bytes_per_particle"] = r.bytesPerParticle;
  j["effective_gb_per_s"] = r.effectiveBytesPerSecond * 1e-9;
  j["copy_gb_per_s"] = run.copy.bytesPerSecond * 1e-9;
  j["copy_fraction"] = r.copyFraction;
  j["clamped_spheres"] = r.clampedSpheres;
  j["large_chunks"] = r.largeChunks;
  j["spilled_spheres"] = r.spilledSpheres;
  if (!run.stopped.empty()) j["stopped"] = run.stopped;
  return j;
}

nlohmann::json sphereRunJson(const SphereBenchRun& run, const ReportInfo& info) {
  const SphereBenchConfig& c = run.config;
  nlohmann::json j = runHeaderJson(info, run.device, run.deviceLocalBytes, run.copy, run.seconds);
  nlohmann::json settings;
  settings["width"] = c.width;
  settings["height"] = c.height;
  settings["cameras"] = c.cameras;
  settings["frames"] = c.frames;
  settings["warmup"] = run.warmup;
  settings["seconds_per_combination"] = c.secondsPerCombination;
  settings["fov"] = c.fovY;
  settings["timing"] =
      "per camera: GPU time of clear + draw + resolve per frame from timestamp queries, median "
      "of the timed frames after the warm-up; per combination: median, min, max over the "
      "cameras of an orbit";
  settings["methods"] = nlohmann::json::array();
  for (SphereMethod m : c.methods)
    settings["methods"].push_back(sphereMethodName(m));
  for (ParticleLayout l : c.layouts)
    settings["layouts"].push_back(particleLayoutName(l));
  for (SphereBillboard b : c.billboards)
    settings["billboards"].push_back(sphereBillboardName(b));
  for (bool conservative : c.conservative)
    settings["conservative"].push_back(conservative);
  for (Orbit o : c.orbits)
    settings["orbits"].push_back(orbitName(o));
  j["settings"] = settings;
  j["datasets"] = nlohmann::json::array();
  for (const DatasetOutcome& d : run.datasets) {
    nlohmann::json dj = datasetJson(d);
    for (const SphereOrbitCameras& cameras : run.cameras)
      if (cameras.dataset == d.dataset.name) dj["cameras"][orbitName(cameras.orbit)] = cameras.cameras;
    j["datasets"].push_back(dj);
  }
  j["skipped_layouts"] = run.skippedLayouts;
  j["results"] = nlohmann::json::array();
  for (const SphereResult& r : run.results)
    j["results"].push_back(sphereResultJson(run, r));
  return j;
}

std::string sphereMarkdownReport(const SphereBenchRun& run, const ReportInfo& info) {
  const SphereBenchConfig& c = run.config;
  const SphereResultIndex index(run);
  const auto datasets = measuredDatasets(run.datasets);
  const std::vector<SphereVariant> variants = sphereVariants(c);
  std::ostringstream md;
  markdownHeader(md, info, run.device, run.deviceLocalBytes, run.copy, run.stopped);
  md << "- Image " << c.width << "x" << c.height << ", vertical field of view " << printf1("%g", c.fovY)
     << " degrees. Per combination, each of an orbit's " << c.cameras << " cameras renders " << run.warmup
     << " warm-up frames and " << c.frames << (c.frames == 1 ? " timed frame" : " timed frames")
     << " (a frame being clear + draw + resolve or attachment copy, timed with timestamp queries); a cell is "
        "the median over the cameras of each camera's median. After each upload, frames of the first "
        "combination are rendered until their time settles, so that GPU clocks that fell to idle during the "
        "host's work are up again.\n";
  {
    size_t shortened = 0;
    uint32_t fewest = c.frames;
    for (const SphereResult& r : run.results)
      if (r.ok() && r.frames < c.frames) {
        ++shortened;
        fewest = std::min(fewest, r.frames);
      }
    if (shortened > 0)
      md << "- Time budget " << printf1("%g", c.secondsPerCombination) << " s per combination: " << shortened
         << " slower combinations were timed over fewer frames per camera (down to " << fewest
         << ", without warm-up after one probe frame; JSON `frames`).\n";
  }
  md << "- Orbits around the center of the spheres' bounds, looking at it, z up: **short** inside the bounds "
        "(an ellipse at half their extent along x and y, a quarter of the half height above the center), "
        "**long** outside them (20 degrees above the horizon, as far as keeps the bounds' enclosing sphere "
        "in "
        "the image). Every camera is listed in the JSON.\n";
  markdownFooter(md, info, run.seconds);

  // Rows: data set x layout x method; columns: billboard x conservative.
  auto table = [&](Orbit orbit, auto&& cell) {
    md << "| data set | layout | method |";
    for (const SphereVariant& v : variants)
      md << " " << v.name() << " |";
    md << "\n| --- | --- | --- |";
    for (size_t k = 0; k < variants.size(); ++k)
      md << " ---: |";
    md << "\n";
    for (const DatasetOutcome* d : datasets)
      for (ParticleLayout layout : c.layouts)
        for (SphereMethod m : c.methods) {
          const bool billboards = sphereMethodTakesBillboards(m);
          std::vector<std::string> cells;
          bool any = false;
          for (size_t k = 0; k < variants.size(); ++k) {
            if (!billboards && k > 0) {
              cells.push_back("-");
              continue;
            }
            const SphereResult* r = index.find(d->dataset.name, layout, orbit, m, variants[k].billboard,
                                               variants[k].conservative);
            any = any || r;
            cells.push_back(!r ? "" : r->ok() ? cell(*r) : "n/a");
          }
          if (!any) continue; // a layout the set cannot be held in
          md << "| " << mdCell(d->dataset.label) << " | " << particleLayoutName(layout) << " | "
             << sphereMethodName(m) << " |";
          for (const std::string& text : cells)
            md << " " << text << " |";
          md << "\n";
        }
    md << "\n";
  };

  for (Orbit o : c.orbits) {
    md << "## " << orbitName(o) << " orbit: median GPU time per frame, ms\n\n";
    md << "Methods that rasterize no billboards (sphere-compute) have one time, in the first column.\n\n";
    table(o, [](const SphereResult& r) { return formatMs(r.medianMs); });
  }

  if (!c.orbits.empty()) {
    const bool hasLong = std::find(c.orbits.begin(), c.orbits.end(), Orbit::Long) != c.orbits.end();
    const Orbit o = hasLong ? Orbit::Long : c.orbits.front();
    md << "## " << orbitName(o) << " orbit: effective bandwidth, % of copy bandwidth\n\n";
    md << "Effective bandwidth = particles x bytes per particle of the layout (";
    for (size_t k = 0; k < c.layouts.size(); ++k)
      md << (k ? ", " : "") << particleLayoutName(c.layouts[k]) << " "
         << particleLayoutInfo(c.layouts[k]).bytesPerParticle;
    md << ") / median time.\n\n";
    table(o, [](const SphereResult& r) { return printf1("%.0f%%", r.copyFraction * 100); });
  }

  // The benchmark target: sphere-compute against the fastest rasterization pipeline.
  const bool compute =
      std::find(c.methods.begin(), c.methods.end(), SphereMethod::Compute) != c.methods.end();
  if (compute && c.methods.size() > 1) {
    md << "## sphere-compute against the fastest other method\n\n";
    md << "The fastest measured setting of each side (over layouts, billboards and conservative "
          "rasterization); speed-up = the other's time / sphere-compute's.\n\n";
    md << "| data set | orbit | sphere-compute | ms | fastest other | ms | speed-up |\n";
    md << "| --- | --- | --- | ---: | --- | ---: | ---: |\n";
    for (const DatasetOutcome* d : datasets)
      for (Orbit o : c.orbits) {
        const SphereResult* mine = fastest(
            run, d->dataset.name, o, [](const SphereResult& r) { return r.method == SphereMethod::Compute; });
        const SphereResult* other = fastest(
            run, d->dataset.name, o, [](const SphereResult& r) { return r.method != SphereMethod::Compute; });
        if (!mine && !other) continue;
        md << "| " << mdCell(d->dataset.label) << " | " << orbitName(o) << " | "
           << (mine ? particleLayoutName(mine->layout) : "n/a") << " | "
           << (mine ? formatMs(mine->medianMs) : "") << " | " << (other ? sphereSetting(*other) : "n/a")
           << " | " << (other ? formatMs(other->medianMs) : "") << " | "
           << (mine && other ? printf1("%.2fx", other->medianMs / mine->medianMs) : "") << " |\n";
      }
    md << "\n";
  }

  // What sphere-points and sphere-compute counted in their frames.
  const bool points = std::find(c.methods.begin(), c.methods.end(), SphereMethod::Points) != c.methods.end();
  if (points || compute) {
    md << "## Per-frame counters (the most of an orbit's cameras)\n\n";
    md << "sphere-points: spheres larger than the device's largest point, drawn incomplete (per billboard, "
          "conservative off); sphere-compute: 256-pixel chunks of large spheres listed, and large spheres "
          "that drew their chunks themselves (list full).\n\n";
    md << "| data set | orbit | layout |";
    for (SphereBillboard b : c.billboards)
      if (points) md << " sphere-points clamped, " << sphereBillboardName(b) << " |";
    if (compute) md << " sphere-compute large chunks | spilled |";
    md << "\n| --- | --- | --- |";
    for (size_t k = 0; k < (points ? c.billboards.size() : 0) + (compute ? 2 : 0); ++k)
      md << " ---: |";
    md << "\n";
    auto count = [](const SphereResult* r, uint64_t SphereResult::*field) {
      return !r ? std::string() : r->ok() ? std::to_string(r->*field) : std::string("n/a");
    };
    for (const DatasetOutcome* d : datasets)
      for (Orbit o : c.orbits)
        for (ParticleLayout layout : c.layouts) {
          std::vector<std::string> cells;
          bool any = false;
          if (points)
            for (SphereBillboard b : c.billboards) {
              const SphereResult* r = index.find(d->dataset.name, layout, o, SphereMethod::Points, b, false);
              any = any || r;
              cells.push_back(count(r, &SphereResult::clampedSpheres));
            }
          if (compute) {
            const SphereResult* r = index.find(d->dataset.name, layout, o, SphereMethod::Compute);
            any = any || r;
            cells.push_back(count(r, &SphereResult::largeChunks));
            cells.push_back(count(r, &SphereResult::spilledSpheres));
          }
          if (!any) continue;
          md << "| " << mdCell(d->dataset.label) << " | " << orbitName(o) << " | "
             << particleLayoutName(layout) << " |";
          for (const std::string& text : cells)
            md << " " << text << " |";
          md << "\n";
        }
    md << "\n";
  }

  markdownDatasets(md, run.datasets);
  std::set<std::string> reasons(run.skippedLayouts.begin(), run.skippedLayouts.end());
  for (const SphereResult& r : run.results)
    if (!r.ok()) {
      const std::string method = sphereMethodName(r.method);
      reasons.insert(r.reason.rfind(method, 0) == 0 ? r.reason : method + ": " + r.reason);
    }
  markdownNotMeasured(md, reasons);
  return md.str();
}

std::string sphereSvgChart(const SphereBenchRun& run, const ReportInfo& info) {
  const SphereBenchConfig& c = run.config;
  BarChart chart;
  chart.title = info.title;
  chart.subtitle = run.device.name + ", " + std::to_string(c.width) + "x" + std::to_string(c.height) +
                   ", each method's fastest layout and billboard, median of " + std::to_string(c.cameras) +
                   " cameras";
  for (SphereMethod m : c.methods)
    chart.series.push_back(sphereMethodName(m));
  for (const DatasetOutcome* d : measuredDatasets(run.datasets))
    for (Orbit o : c.orbits) {
      chart.groups.push_back(d->dataset.name + " (" + orbitName(o) + " orbit)");
      std::vector<double>& values = chart.values.emplace_back();
      for (SphereMethod m : c.methods) {
        bool tried = false;
        for (const SphereResult& r : run.results)
          tried = tried || (r.dataset == d->dataset.name && r.orbit == o && r.method == m);
        const SphereResult* best =
            fastest(run, d->dataset.name, o, [m](const SphereResult& r) { return r.method == m; });
        values.push_back(best ? best->medianMs : tried ? kNotMeasured : kNoBar);
      }
    }
  return svgBars(chart);
}

WrittenFiles writeSphereReports(const SphereBenchRun& run, const ReportInfo& info,
                                const std::filesystem::path& dir) {
  return writeReportFiles(dir, info.name, jsonFileText(sphereRunJson(run, info)),
                          sphereMarkdownReport(run, info), sphereSvgChart(run, info));
}

} // namespace pointrast::bench

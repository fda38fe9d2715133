// The point suites' reports (paper2021, paper2022, lod, vr2022 share them): see bench/report.h.
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
#include "base/progress.h"
#include "bench/lod_report.h"
#include "bench/report_parts.h"
#include "bench/suites.h"

namespace pointrast::bench {

namespace {

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

// The order and view the chart and the bandwidth table show: Morton / overview when measured.
Order chartOrder(const BenchConfig& c) {
  bool morton = std::find(c.orders.begin(), c.orders.end(), Order::Morton) != c.orders.end();
  return morton || c.orders.empty() ? Order::Morton : c.orders.front();
}
View mainView(const BenchConfig& c) {
  bool overview = std::find(c.views.begin(), c.views.end(), View::Overview) != c.views.end();
  return overview || c.views.empty() ? View::Overview : c.views.front();
}

} // namespace

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
  if (!r.ranks.is_null()) j["mpi"] = r.ranks;
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

namespace {

// The run's own settings: image, frames, how a frame is timed, and what the time budget shortened.
void markdownSettings(std::ostringstream& md, const BenchRun& run) {
  const BenchConfig& c = run.config;
  md << "- Image " << c.width << "x" << c.height << ", vertical field of view " << printf1("%g", c.fovY)
     << " degrees; each cell is the median GPU time of " << c.frames << " frames after " << run.warmup
     << " warm-up frames, a frame being clear + render + resolve, timed with timestamp queries. After each "
        "upload, frames of the first method are rendered until their time settles, so that GPU clocks that "
        "fell to idle during the host's work are up again.\n";
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
  if (shortened.empty()) return;
  md << "- Time budget " << printf1("%g", c.secondsPerCombination)
     << " s per combination: slower combinations were timed over fewer frames after 1 warm-up frame "
        "(JSON `frames`):";
  for (const auto& [name, s] : shortened)
    md << " " << name << " " << s.combinations << "x (" << s.fewest
       << (s.most != s.fewest ? "-" + std::to_string(s.most) : "") << " frames);";
  md << "\n";
}

// What the point report's tables read: the run, its results by key and the measured data sets.
struct PointTables {
  const BenchRun& run;
  ResultIndex index;
  std::vector<const DatasetOutcome*> datasets;
};

// One table of a view, laid out like Table 1 of the 2021 paper: rows data set x order, a column per
// method, `cell` of each measured result.
template <class Cell> void methodTable(std::ostringstream& md, const PointTables& t, View view, Cell&& cell) {
  const BenchConfig& c = t.run.config;
  md << "| data set | order |";
  for (Method m : c.methods)
    md << " " << methodName(m) << " |";
  md << "\n| --- | --- |";
  for (size_t k = 0; k < c.methods.size(); ++k)
    md << " ---: |";
  md << "\n";
  for (const DatasetOutcome* d : t.datasets) {
    for (Order o : c.orders) {
      // A data set measured in fewer orders or views than the run (a suite's choice) has no row here.
      bool any = false;
      for (Method m : c.methods)
        any = any || t.index.find(d->dataset.name, o, view, m);
      if (!any) continue;
      md << "| " << mdCell(d->dataset.label) << " | " << orderName(o) << " |";
      for (Method m : c.methods) {
        const Result* r = t.index.find(d->dataset.name, o, view, m);
        md << " " << (!r ? "" : r->ok() ? cell(*r) : std::string("n/a")) << " |";
      }
      md << "\n";
    }
  }
  md << "\n";
}

// The main view's effective bandwidth as a share of the copy bandwidth, and what each method counts.
void markdownBandwidth(std::ostringstream& md, const PointTables& t) {
  const BenchConfig& c = t.run.config;
  if (c.views.empty()) return;
  const View bandwidthView = mainView(c);
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
          "(depth and blending pass) and the color of each blended point, except that batch-hqs reads the "
          "words of a dense batch once (twice if it draws the batch again) and all its colors in the first "
          "pass.";
  md << "\n\n";
  methodTable(md, t, bandwidthView, [](const Result& r) { return printf1("%.0f%%", r.copyFraction * 100); });
}

// One row of the batch statistics table.
void batchStatisticsRow(std::ostringstream& md, const DatasetOutcome& d, Order o, View v, Method m,
                        const Result& r) {
  const BatchStats& b = *r.stats.batch;
  auto count = [](uint64_t n) { return shortCount(n); };
  auto share = [&](uint64_t n) {
    return b.pointsProcessed ? printf1("%.0f%%", 100.0 * double(n) / double(b.pointsProcessed))
                             : std::string("-");
  };
  md << "| " << mdCell(d.dataset.label) << " | " << orderName(o) << " | " << viewName(v) << " | "
     << methodName(m) << " | " << b.batchesProcessed << " | " << b.batchesRendered << " | "
     << count(b.pointsProcessed) << " | " << share(b.pointsByWords[0]) << " / " << share(b.pointsByWords[1])
     << " / " << share(b.pointsByWords[2]) << " | " << count(b.pointsRendered) << " | "
     << (m.info().output == MethodOutput::Blend ? count(b.pointsBlended) : "-") << " | "
     << formatMs(r.stats.medianMs) << " |\n";
}

// The 2022 paper's Table 2: what the batch methods processed and rendered, per frame (the LOD rows have
// their own table).
void markdownBatchStatistics(std::ostringstream& md, const PointTables& t) {
  const BenchConfig& c = t.run.config;
  auto batchRow = [](const Result* r) { return r && r->ok() && r->stats.batch && !r->stats.lod; };
  bool any = false;
  for (const Result& r : t.run.results)
    any = any || batchRow(&r);
  if (!any) return;
  md << "## Batch statistics per frame (the 2022 paper's Table 2)\n\n";
  md << "Batches of 10,240 points: processed (all), rendered (not culled); points processed (in rendered "
        "batches) and how many coordinate words they needed; points rendered (passed early-z and did the "
        "atomic); batch-hqs: points blended.\n\n";
  md << "| data set | order | view | method | batches | rendered | points processed | 1 / 2 / 3 words | "
        "points rendered | blended | ms |\n";
  md << "| --- | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const DatasetOutcome* d : t.datasets)
    for (Order o : c.orders)
      for (View v : c.views)
        for (Method m : c.methods) {
          const Result* r = t.index.find(d->dataset.name, o, v, m);
          if (batchRow(r)) batchStatisticsRow(md, *d, o, v, m, *r);
        }
  md << "\n";
}

} // namespace

// A run on several processes (BenchRanks): each combination's frame time on every rank and the composite's
// cost; the tables above show the slowest rank's time, when the job's frame is done.
static void markdownRanks(std::ostringstream& md, const BenchRun& run) {
  bool any = false;
  for (const Result& r : run.results)
    any = any || !r.ranks.is_null();
  if (!any) return;
  md << "## Ranks: median GPU time per frame of each rank, and the composite on rank 0\n\n"
     << "| data set | order | view | method | ranks | each rank, ms | points per rank | readback, ms | "
        "composite (MIN), ms | resolve, ms | MB moved |\n"
     << "|---|---|---|---|---:|---|---|---:|---:|---:|---:|\n";
  for (const Result& r : run.results) {
    if (r.ranks.is_null()) continue;
    const nlohmann::json& m = r.ranks;
    std::string each, points;
    for (const nlohmann::json& ms : m["rank_render_ms"])
      each += (each.empty() ? "" : ", ") + formatMs(ms.get<double>());
    for (const nlohmann::json& p : m["rank_points"])
      points += (points.empty() ? "" : ", ") + humanCount(p.get<double>());
    md << "| " << r.dataset << " | " << orderName(r.order) << " | " << viewName(r.view) << " | "
       << methodName(r.method) << " | " << m["ranks"].get<uint32_t>() << " | " << each << " | " << points
       << " | " << formatMs(m["readback_ms"].get<double>()) << " | "
       << formatMs(m["composite_ms"].get<double>()) << " | " << formatMs(m["resolve_ms"].get<double>())
       << " | " << printf1("%.1f", m["bytes_moved"].get<double>() / 1e6) << " |\n";
  }
  md << "\n";
}

std::string markdownReport(const BenchRun& run, const ReportInfo& info) {
  const PointTables tables{run, ResultIndex(run), measuredDatasets(run.datasets)};
  std::ostringstream md;
  markdownHeader(md, info, run.device, run.deviceLocalBytes, run.copy, run.stopped);
  markdownSettings(md, run);
  markdownFooter(md, info, run.seconds);
  for (View v : run.config.views) {
    md << "## " << viewName(v) << ": median GPU time per frame, ms\n\n";
    methodTable(md, tables, v, [](const Result& r) { return formatMs(r.stats.medianMs); });
  }
  markdownBandwidth(md, tables);
  markdownRanks(md, run);
  markdownBatchStatistics(md, tables);
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

} // namespace pointrast::bench

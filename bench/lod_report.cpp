#include "bench/lod_report.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "base/text.h"
#include "bench/lod_suite.h"
#include "bench/report.h"
#include "bench/report_parts.h"
#include "bench/suites.h"

namespace pointrast::bench {

namespace {

// The batch-prefetch result of the same data set and view, if the run has one (the fastest brute-force
// method of the 2022 paper, which the LOD speed-up is measured against).
const Result* bruteForceOf(const BenchRun& run, const Result& lod) {
  const Result* found = nullptr;
  for (const Result& r : run.results)
    if (r.ok() && r.dataset == lod.dataset && r.view == lod.view &&
        r.method == pointMethod("batch-prefetch") && (!found || r.order == Order::Morton))
      found = &r;
  return found;
}

} // namespace

void markdownOctrees(std::ostream& md, const std::vector<std::pair<std::string, DatasetOctree>>& octrees) {
  md << "| data set | points | bytes | build s | reused | phases |\n| --- | ---: | ---: | ---: | --- | --- "
        "|\n";
  for (const auto& [dataset, o] : octrees)
    md << "| " << dataset << " | " << shortCount(o.points) << " | " << bytesText(o.bytes) << " | "
       << printf1("%.1f", o.buildSeconds) << " | " << (o.reused ? "yes" : "no") << " | " << o.phases
       << " |\n";
  md << "\n";
}

nlohmann::json octreesJson(const std::vector<std::pair<std::string, DatasetOctree>>& octrees) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& [dataset, o] : octrees)
    list.push_back({{"dataset", dataset},
                    {"path", o.path.string()},
                    {"reused", o.reused},
                    {"build_seconds", o.buildSeconds},
                    {"points", o.points},
                    {"bytes", o.bytes},
                    {"phases", o.phases}});
  return list;
}

void markdownLodStatistics(std::ostream& md, const BenchRun& run) {
  std::vector<const Result*> rows;
  for (const Result& r : run.results)
    if (r.ok() && r.stats.lod && r.stats.batch) rows.push_back(&r);
  if (rows.empty()) return;
  md << "## LOD statistics per frame (the 2022 paper's Table 2, octrees)\n\n";
  md << "Octree nodes selected on the CPU (projected size >= --min-node-px 100, parents first) and the "
        "points "
        "they hold; nodes processed on the GPU and rendered (not culled), points processed (in rendered "
        "nodes) and how many coordinate words they needed, points rendered (passed early-z and did the "
        "atomic), lod-hqs: points blended. Speed-up: batch-prefetch's time from the same camera (Morton "
        "order) over the LOD method's.\n\n";
  md << "| data set | view | method | nodes | rendered | points selected | points processed | 1 / 2 / 3 "
        "words | "
        "points rendered | blended | ms | speed-up |\n";
  md << "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const Result* r : rows) {
    const BatchStats& b = *r->stats.batch;
    const lod::LodStats& l = *r->stats.lod;
    auto share = [&](uint64_t n) {
      return b.pointsProcessed ? printf1("%.0f%%", 100.0 * double(n) / double(b.pointsProcessed))
                               : std::string("-");
    };
    const Result* brute = bruteForceOf(run, *r);
    std::string label = r->dataset;
    for (const DatasetOutcome& d : run.datasets)
      if (d.dataset.name == r->dataset) label = d.dataset.label;
    md << "| " << label << " | " << viewName(r->view) << " | " << methodName(r->method) << " | "
       << l.nodesSelected << " | " << b.batchesRendered << " | " << shortCount(l.pointsSelected) << " | "
       << shortCount(b.pointsProcessed) << " | " << share(b.pointsByWords[0]) << " / "
       << share(b.pointsByWords[1]) << " / " << share(b.pointsByWords[2]) << " | "
       << shortCount(b.pointsRendered) << " | "
       << (methodInfo(r->method).output == MethodOutput::Blend ? shortCount(b.pointsBlended) : "-") << " | "
       << formatMs(r->stats.medianMs) << " | "
       << (brute && r->stats.medianMs > 0 ? printf1("%.2fx", brute->stats.medianMs / r->stats.medianMs) : "-")
       << " |\n";
  }
  md << "\n";
  if (run.octrees.empty()) return;
  md << "### Octrees\n\n";
  md << "Built once from each data set's points with the octree builder (`pointrast lod`) and kept in the "
        "octree cache; a reused octree shows the time of its build.\n\n";
  markdownOctrees(md, run.octrees);
}

} // namespace pointrast::bench

namespace pointrast::bench {

namespace {

constexpr double kFrameMs60 = 1000.0 / 60.0; // the 60 fps target
constexpr uint32_t kConvergeFrames = 30;     // the jump target

std::string budgetName(uint64_t budget) {
  return budget ? shortCount(budget) : "none";
}

std::vector<double> gpuMs(const std::vector<LodFrameSample>& frames) {
  std::vector<double> v;
  for (const LodFrameSample& f : frames)
    v.push_back(f.gpuMs);
  return v;
}

std::vector<double> wallMs(const std::vector<LodFrameSample>& frames) {
  std::vector<double> v;
  for (const LodFrameSample& f : frames)
    v.push_back(f.wallMs);
  return v;
}

size_t over(const std::vector<double>& ms, double limit) {
  return size_t(std::count_if(ms.begin(), ms.end(), [&](double v) { return v > limit; }));
}

nlohmann::json msJson(const std::vector<double>& ms) {
  return {{"median", percentile(ms, 0.5)},
          {"p99", percentile(ms, 0.99)},
          {"max", percentile(ms, 1.0)},
          {"over_16_7", over(ms, kFrameMs60)}};
}

std::string datasetLabel(const LodSuiteRun& run, const std::string& name) {
  for (const DatasetOutcome& d : run.datasets)
    if (d.dataset.name == name) return d.dataset.label;
  return name;
}

double gbPerSecond(uint64_t bytes, double seconds) {
  return seconds > 0 ? double(bytes) * 1e-9 / seconds : 0.0;
}

// The sweep's table: rows data set x view, one column per value of `values`, cells "ms (points drawn)".
template <class Value, class Match, class Name>
void sweepTable(std::ostringstream& md, const LodSuiteRun& run, const std::vector<Value>& values,
                Match&& match, Name&& name) {
  md << "| data set | view |";
  for (const Value& v : values)
    md << " " << name(v) << " |";
  md << "\n| --- | --- |";
  for (size_t k = 0; k < values.size(); ++k)
    md << " ---: |";
  md << "\n";
  for (const DatasetOutcome& d : run.datasets)
    for (View view : run.config.views) {
      bool any = false;
      std::ostringstream row;
      row << "| " << d.dataset.label << " | " << viewName(view) << " |";
      for (const Value& v : values) {
        const LodSweepResult* found = nullptr;
        for (const LodSweepResult& r : run.sweeps)
          if (r.dataset == d.dataset.name && r.view == view && match(r, v)) found = &r;
        any = any || found;
        row << " "
            << (!found        ? std::string()
                : found->ok() ? formatMs(found->stats.medianMs) + " (" + shortCount(found->stats.points) + ")"
                              : std::string("n/a"))
            << " |";
      }
      if (any) md << row.str() << "\n";
    }
  md << "\n";
}

void streamMarkdown(std::ostringstream& md, const LodSuiteRun& run, const LodStreamResult& s) {
  md << "### " << datasetLabel(run, s.dataset) << "\n\n";
  if (!s.ok()) {
    md << "Not measured: " << s.reason << "\n\n";
    return;
  }
  md << "- Octree: " << shortCount(s.octreePoints) << " points, " << bytesText(s.octreeGpuBytes)
     << " in the node cache's pages; node cache (`--gpu-memory`) " << bytesText(s.cacheBytes) << ", "
     << printf1("%.1f", s.cacheBytes ? double(s.octreeGpuBytes) / double(s.cacheBytes) : 0.0)
     << "x smaller than the octree.\n";
  md << "- The octree's files were " << (s.pageCacheDropped ? "" : "**not** ")
     << "dropped from the page cache before streaming"
     << (s.pageCacheDropped ? " (nodes were read from disk)" : " (nodes may have come from memory)") << ".\n";
  if (!s.flight.empty()) {
    const std::vector<double> gpu = gpuMs(s.flight), wall = wallMs(s.flight);
    uint64_t streamed = s.flight.back().bytesStreamed;
    double seconds = 0;
    for (const LodFrameSample& f : s.flight)
      seconds += f.wallMs * 1e-3;
    md << "- Flight: " << s.flight.size() << " frames from `" << s.flightCameras.front() << "` to `"
       << s.flightCameras.back() << "`.\n\n";
    md << "| frames | GPU ms median / p99 / max | frames over 16.7 ms (GPU) | wall ms median / p99 / max | "
          "frames "
          "over 16.7 ms (wall) | converged frames | streamed | GB/s |\n";
    md << "| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    md << "| " << s.flight.size() << " | " << formatMs(percentile(gpu, 0.5)) << " / "
       << formatMs(percentile(gpu, 0.99)) << " / " << formatMs(percentile(gpu, 1.0)) << " | "
       << over(gpu, kFrameMs60) << " | " << formatMs(percentile(wall, 0.5)) << " / "
       << formatMs(percentile(wall, 0.99)) << " / " << formatMs(percentile(wall, 1.0)) << " | "
       << over(wall, kFrameMs60) << " | "
       << std::count_if(s.flight.begin(), s.flight.end(), [](const LodFrameSample& f) { return f.converged; })
       << " | " << bytesText(streamed) << " | " << printf1("%.2f", gbPerSecond(streamed, seconds))
       << " |\n\n";
  }
  if (!s.jumps.empty()) {
    md << "| jump | frames to converge | s | streamed | GB/s | max GPU ms | max wall ms |\n";
    md << "| ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    for (size_t k = 0; k < s.jumps.size(); ++k) {
      const LodJumpResult& j = s.jumps[k];
      md << "| " << k + 1 << " | "
         << (j.converged ? std::to_string(j.frames) : "not in " + std::to_string(j.frames)) << " | "
         << printf1("%.2f", j.seconds) << " | " << bytesText(j.bytesStreamed) << " | "
         << printf1("%.2f", gbPerSecond(j.bytesStreamed, j.seconds)) << " | " << formatMs(j.maxGpuMs) << " | "
         << formatMs(j.maxWallMs) << " |\n";
    }
    md << "\n";
  }
  const std::vector<double> gpu = gpuMs(s.flight), wall = wallMs(s.flight);
  const size_t convergedInTime =
      size_t(std::count_if(s.jumps.begin(), s.jumps.end(), [](const LodJumpResult& j) {
        return j.converged && j.frames <= kConvergeFrames;
      }));
  md << "Targets: every frame of the flight at >= 60 fps: **"
     << (over(gpu, kFrameMs60) == 0 ? "met" : "missed") << "** by GPU time, **"
     << (over(wall, kFrameMs60) == 0 ? "met" : "missed") << "** by wall time; converged within "
     << kConvergeFrames << " frames of a jump: **" << convergedInTime << " of " << s.jumps.size()
     << "** jumps.\n\n";
}

} // namespace

nlohmann::json lodStreamJson(const LodStreamResult& s) {
  nlohmann::json j;
  j["dataset"] = s.dataset;
  j["status"] = s.status;
  if (!s.reason.empty()) j["reason"] = s.reason;
  j["octree_points"] = s.octreePoints;
  j["octree_gpu_bytes"] = s.octreeGpuBytes;
  j["cache_bytes"] = s.cacheBytes;
  j["page_cache_dropped"] = s.pageCacheDropped;
  j["flight_cameras"] = s.flightCameras;
  const std::vector<double> gpu = gpuMs(s.flight), wall = wallMs(s.flight);
  j["flight"] = {
      {"frames", s.flight.size()}, {"gpu_ms", msJson(gpu)},
      {"wall_ms", msJson(wall)},   {"bytes_streamed", s.flight.empty() ? 0 : s.flight.back().bytesStreamed},
      {"per_frame_gpu_ms", gpu},   {"per_frame_wall_ms", wall}};
  nlohmann::json points = nlohmann::json::array();
  for (const LodFrameSample& f : s.flight)
    points.push_back(f.pointsDrawn);
  j["flight"]["per_frame_points_drawn"] = points;
  j["jumps"] = nlohmann::json::array();
  for (const LodJumpResult& jump : s.jumps)
    j["jumps"].push_back({{"camera", jump.camera},
                          {"frames", jump.frames},
                          {"converged", jump.converged},
                          {"seconds", jump.seconds},
                          {"bytes_streamed", jump.bytesStreamed},
                          {"gb_per_s", gbPerSecond(jump.bytesStreamed, jump.seconds)},
                          {"max_gpu_ms", jump.maxGpuMs},
                          {"max_wall_ms", jump.maxWallMs}});
  j["lod_stats"] = lodStatsJson(s.last);
  return j;
}

nlohmann::json lodSuiteJson(const LodSuiteRun& run, const ReportInfo& info) {
  nlohmann::json j = runHeaderJson(info, run.device, run.deviceLocalBytes, run.copy, run.seconds);
  const LodSuiteConfig& c = run.config;
  j["settings"] = {{"width", c.width},
                   {"height", c.height},
                   {"frames", c.frames},
                   {"warmup", run.warmup},
                   {"fov", c.fovY},
                   {"point_budgets", c.pointBudgets},
                   {"min_node_px", c.minNodePx},
                   {"cache_divisor", c.cacheDivisor},
                   {"flight_frames", c.flightFrames},
                   {"jumps", c.jumps},
                   {"jump_frame_limit", c.jumpFrameLimit},
                   {"display_hz", c.displayHz}};
  if (!run.stopped.empty()) j["stopped"] = run.stopped;
  j["datasets"] = nlohmann::json::array();
  for (const DatasetOutcome& d : run.datasets)
    j["datasets"].push_back(datasetJson(d));
  j["octrees"] = octreesJson(run.octrees);
  j["sweeps"] = nlohmann::json::array();
  for (const LodSweepResult& r : run.sweeps) {
    nlohmann::json s = {{"dataset", r.dataset},       {"view", viewName(r.view)},
                        {"min_node_px", r.minNodePx}, {"point_budget", r.pointBudget},
                        {"status", r.status},         {"camera", r.camera}};
    if (!r.reason.empty()) s["reason"] = r.reason;
    if (r.ok()) {
      s["frames"] = r.stats.frames;
      s["median_ms"] = r.stats.medianMs;
      s["min_ms"] = r.stats.minMs;
      s["max_ms"] = r.stats.maxMs;
      s["points"] = r.stats.points;
      if (r.stats.batch) s["batch_stats"] = batchStatsJson(*r.stats.batch);
      if (r.stats.lod) s["lod_stats"] = lodStatsJson(*r.stats.lod);
    }
    j["sweeps"].push_back(s);
  }
  j["streams"] = nlohmann::json::array();
  for (const LodStreamResult& s : run.streams)
    j["streams"].push_back(lodStreamJson(s));
  return j;
}

std::string lodSuiteMarkdown(const LodSuiteRun& run, const ReportInfo& info) {
  const LodSuiteConfig& c = run.config;
  std::ostringstream md;
  markdownHeader(md, info, run.device, run.deviceLocalBytes, run.copy, run.stopped);
  md << "- Image " << c.width << "x" << c.height << ", vertical field of view " << printf1("%g", c.fovY)
     << " degrees, method `lod`. Sweeps: each cell is the median GPU time of " << c.frames << " frames after "
     << run.warmup << " warm-up frames (clear + nodes + draw + resolve, timestamp queries), the selection "
     << "streamed in before, with the number of points drawn in parentheses; a selection larger than the "
        "node "
        "cache (half the device) is drawn in passes, its time the sum of theirs.\n";
  md << "- Streaming: the node cache holds 1/" << c.cacheDivisor << " of the octree; every frame is one "
     << "`Renderer::renderFrame` (select, upload what the readers finished, draw the resident nodes), paced "
        "at "
     << printf1("%g", c.displayHz) << " Hz like a display. GPU ms: timestamps around the frame's uploads and "
     << "drawing; wall ms: the whole call, host work included. A jump counts the frames until the frame "
        "drew its whole selection (at most "
     << c.jumpFrameLimit << ").\n";
  markdownFooter(md, info, run.seconds);
  md << "## Render time against the point budget (--min-node-px 100), ms (points drawn)\n\n";
  sweepTable(
      md, run, c.pointBudgets,
      [](const LodSweepResult& r, uint64_t b) { return r.pointBudget == b && r.minNodePx == 100; },
      [](uint64_t b) { return budgetName(b); });
  md << "## Render time against --min-node-px (no budget), ms (points drawn)\n\n";
  sweepTable(
      md, run, c.minNodePx,
      [](const LodSweepResult& r, double px) { return r.pointBudget == 0 && r.minNodePx == px; },
      [](double px) { return printf1("%g px", px); });
  md << "## Streaming\n\n";
  for (const LodStreamResult& s : run.streams)
    streamMarkdown(md, run, s);
  if (!run.octrees.empty()) {
    md << "## Octrees\n\n";
    markdownOctrees(md, run.octrees);
  }
  markdownDatasets(md, run.datasets);
  std::set<std::string> reasons;
  for (const LodSweepResult& r : run.sweeps)
    if (!r.ok()) reasons.insert(r.reason);
  markdownNotMeasured(md, reasons);
  return md.str();
}

std::string lodSuiteSvg(const LodSuiteRun& run, const ReportInfo& info) {
  BarChart chart;
  chart.title = info.title;
  chart.subtitle = run.device.name + ", " + std::to_string(run.config.width) + "x" +
                   std::to_string(run.config.height) + ", lod against the point budget (--min-node-px 100)";
  for (uint64_t b : run.config.pointBudgets)
    chart.series.push_back("budget " + budgetName(b));
  for (const DatasetOutcome& d : run.datasets)
    for (View view : run.config.views) {
      std::vector<double> values;
      bool any = false;
      for (uint64_t b : run.config.pointBudgets) {
        double v = kNoBar;
        for (const LodSweepResult& r : run.sweeps)
          if (r.dataset == d.dataset.name && r.view == view && r.pointBudget == b && r.minNodePx == 100)
            v = r.ok() ? r.stats.medianMs : kNotMeasured;
        any = any || v != kNoBar;
        values.push_back(v);
      }
      if (!any) continue;
      chart.groups.push_back(d.dataset.name + " (" + viewName(view) + ")");
      chart.values.push_back(values);
    }
  return svgBars(chart);
}

WrittenFiles writeLodSuiteReports(const LodSuiteRun& run, const ReportInfo& info,
                                  const std::filesystem::path& dir) {
  return writeReportFiles(dir, info.name, jsonFileText(lodSuiteJson(run, info)), lodSuiteMarkdown(run, info),
                          lodSuiteSvg(run, info));
}

} // namespace pointrast::bench

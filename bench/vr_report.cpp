#include "bench/vr_report.h"

#include <set>
#include <sstream>

#include "bench/lod_report.h"
#include "bench/report_parts.h"
#include "bench/suites.h"

namespace pointrast::bench {

namespace {

// The measurement of a configuration drawn one way (nullptr where there is none).
const VrResult* find(const VrSuiteRun& run, const std::string& dataset, View view, const std::string& name,
                     bool stereo) {
  for (const VrResult& r : run.results)
    if (r.dataset == dataset && r.view == view && r.caseName == name && r.stereo == stereo) return &r;
  return nullptr;
}

std::string msText(const VrResult* r) {
  if (!r) return "";
  return r->ok() ? printf1("%.3f", r->medianMs) : "n/a";
}

// The resolve stage's milliseconds of a measurement, over its passes (0 when it did not run).
double resolveMs(const VrResult& r) {
  double ms = 0;
  for (const FrameStats& f : r.passes)
    if (f.post) ms += f.post->splatMs + f.post->dilateMs + f.post->composeMs;
  return ms;
}

uint64_t pointsDrawn(const VrResult& r) {
  uint64_t n = 0;
  for (const FrameStats& f : r.passes)
    if (f.lod) n += f.lod->pointsDrawn;
  return n;
}

nlohmann::json passJson(const FrameStats& f) {
  nlohmann::json j = {
      {"median_ms", f.medianMs}, {"min_ms", f.minMs}, {"max_ms", f.maxMs}, {"frames", f.frames}};
  if (f.batch) j["batch_stats"] = batchStatsJson(*f.batch);
  if (f.lod) j["lod_stats"] = lodStatsJson(*f.lod);
  if (f.post)
    j["resolve_stage_ms"] = {
        {"splat", f.post->splatMs}, {"dilate", f.post->dilateMs}, {"compose", f.post->composeMs}};
  return j;
}

} // namespace

nlohmann::json vrSuiteJson(const VrSuiteRun& run, const ReportInfo& info) {
  nlohmann::json j = runHeaderJson(info, run.device, run.deviceLocalBytes, run.copy, run.seconds);
  const VrSuiteConfig& c = run.config;
  nlohmann::json views = nlohmann::json::array();
  for (View v : c.views)
    views.push_back(viewName(v));
  j["settings"] = {
      {"eye_width", c.width},
      {"eye_height", c.height},
      {"fov", c.fovY},
      {"ipd", c.ipd},
      {"convergence", "inf"},
      {"min_node_px", c.minNodePx},
      {"fovea_radius", c.foveation.radius},
      {"fovea_periphery", c.foveation.periphery},
      {"dilate", c.dilate},
      {"frames", c.frames},
      {"warmup", run.warmup},
      {"views", views},
      {"targets", {{"vr_frame_ms", kVrFrameTargetMs}, {"stereo_speedup", kStereoSpeedupTarget}}}};
  nlohmann::json cases = nlohmann::json::array();
  for (const VrCase& k : vrCases())
    cases.push_back({{"name", k.name},
                     {"method", k.method},
                     {"foveated", k.foveated},
                     {"dilate", k.dilate},
                     {"one_eye", k.oneEye}});
  j["cases"] = cases;
  if (!run.stopped.empty()) j["stopped"] = run.stopped;
  j["datasets"] = nlohmann::json::array();
  for (const DatasetOutcome& d : run.datasets)
    j["datasets"].push_back(datasetJson(d));
  j["octrees"] = octreesJson(run.octrees);
  j["results"] = nlohmann::json::array();
  for (const VrResult& r : run.results) {
    nlohmann::json x = {{"dataset", r.dataset}, {"view", viewName(r.view)},
                        {"case", r.caseName},   {"pass", r.stereo ? "stereo" : "mono"},
                        {"status", r.status},   {"camera", r.camera}};
    if (!r.reason.empty()) x["reason"] = r.reason;
    if (r.ok()) {
      x["median_ms"] = r.medianMs;
      x["points_drawn"] = pointsDrawn(r);
      x["resolve_stage_ms"] = resolveMs(r);
      if (r.stereo) x["speedup_over_two_mono"] = stereoSpeedup(run, r);
      x["passes"] = nlohmann::json::array();
      for (const FrameStats& f : r.passes)
        x["passes"].push_back(passJson(f));
    }
    j["results"].push_back(x);
  }
  return j;
}

std::string vrSuiteMarkdown(const VrSuiteRun& run, const ReportInfo& info) {
  const VrSuiteConfig& c = run.config;
  std::ostringstream md;
  markdownHeader(md, info, run.device, run.deviceLocalBytes, run.copy, run.stopped);
  md << "- Each eye " << c.width << "x" << c.height << " pixels, vertical field of view "
     << printf1("%g", c.fovY) << " degrees, parallel eyes " << printf1("%g", c.ipd)
     << " scene units apart; --min-node-px " << printf1("%g", c.minNodePx) << " in the fovea (radius "
     << printf1("%g", c.foveation.radius) << " half-diagonals) growing to "
     << printf1("%g", c.minNodePx * c.foveation.periphery) << " px at the corners; dilation radius "
     << c.dilate << ". Each figure is the median GPU time of " << c.frames << " frames after " << run.warmup
     << " warm-up frames (clear + nodes + draw + resolve + resolve stage, timestamp queries), the selection "
        "streamed in before. Stereo: both eyes in one pass (each node's points read once, projected into "
        "both halves); two mono: each eye rendered alone, their medians added.\n";
  md << "- Targets: the VR frame (stereo, lod-hqs, foveated, dilation) within "
     << printf1("%g", kVrFrameTargetMs) << " ms; the stereo pass at least "
     << printf1("%g", kStereoSpeedupTarget) << "x faster than two mono renders.\n";
  markdownFooter(md, info, run.seconds);
  for (const DatasetOutcome& d : run.datasets) {
    if (d.skipped) continue;
    for (View view : c.views) {
      md << "## " << d.dataset.label << ", " << viewName(view) << "\n\n";
      md << "| configuration | stereo ms | two mono ms | speed-up | points drawn (stereo) | resolve stage ms "
            "| target |\n| --- | ---: | ---: | ---: | ---: | ---: | --- |\n";
      for (const VrCase& k : vrCases()) {
        const VrResult* s = find(run, d.dataset.name, view, k.name, true);
        const VrResult* m = find(run, d.dataset.name, view, k.name, false);
        if (!s && !m) continue;
        std::string target;
        if (s && s->ok()) {
          const double speedup = stereoSpeedup(run, *s);
          if (k.name == vrCases().front().name)
            target = std::string(s->medianMs <= kVrFrameTargetMs ? "met" : "missed") + " (" +
                     printf1("%g", kVrFrameTargetMs) + " ms)";
          target += std::string(target.empty() ? "" : "; ") + "speed-up " +
                    (speedup >= kStereoSpeedupTarget ? "met" : "missed");
        }
        md << "| " << k.name << (k.oneEye ? " (mono: the left eye alone)" : "") << " | " << msText(s) << " | "
           << msText(m) << " | "
           << (s && s->ok() && m && m->ok() ? printf1("%.2fx", stereoSpeedup(run, *s)) : "") << " | "
           << (s && s->ok()   ? shortCount(pointsDrawn(*s))
               : m && m->ok() ? shortCount(pointsDrawn(*m))
                              : "")
           << " | "
           << (s && s->ok()   ? printf1("%.3f", resolveMs(*s))
               : m && m->ok() ? printf1("%.3f", resolveMs(*m))
                              : "")
           << " | " << target << " |\n";
      }
      md << "\n";
    }
  }
  if (!run.octrees.empty()) {
    md << "## Octrees\n\n";
    markdownOctrees(md, run.octrees);
  }
  markdownDatasets(md, run.datasets);
  std::set<std::string> reasons;
  for (const VrResult& r : run.results)
    if (!r.ok()) reasons.insert(r.reason);
  markdownNotMeasured(md, reasons);
  return md.str();
}

std::string vrSuiteSvg(const VrSuiteRun& run, const ReportInfo& info) {
  BarChart chart;
  chart.title = info.title;
  chart.subtitle = run.device.name + ", 2 x " + std::to_string(run.config.width) + "x" +
                   std::to_string(run.config.height) + ", stereo pass against two mono renders";
  chart.series = {"stereo", "two mono"};
  for (const DatasetOutcome& d : run.datasets)
    for (View view : run.config.views)
      for (const VrCase& k : vrCases()) {
        if (k.oneEye) continue;
        const VrResult* s = find(run, d.dataset.name, view, k.name, true);
        const VrResult* m = find(run, d.dataset.name, view, k.name, false);
        if (!s && !m) continue;
        auto value = [](const VrResult* r) { return !r ? kNoBar : r->ok() ? r->medianMs : kNotMeasured; };
        chart.groups.push_back(k.name + " (" + viewName(view) + ")");
        chart.values.push_back({value(s), value(m)});
      }
  return svgBars(chart);
}

WrittenFiles writeVrSuiteReports(const VrSuiteRun& run, const ReportInfo& info,
                                 const std::filesystem::path& dir) {
  return writeReportFiles(dir, info.name, jsonFileText(vrSuiteJson(run, info)), vrSuiteMarkdown(run, info),
                          vrSuiteSvg(run, info));
}

} // namespace pointrast::bench

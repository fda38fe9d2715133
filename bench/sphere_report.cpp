// The sphere suite's reports (spheres2023): see bench/report.h.
#include "bench/report.h"

#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "base/error.h"
#include "bench/report_parts.h"
#include "bench/suites.h"

namespace pointrast::bench {

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
  j["batches"] = r.batches;
  j["visible_batches"] = r.visibleBatches;
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

namespace {

// What the sphere report's tables read: the run, its results by key, the measured data sets and the
// billboard settings (the tables' columns).
struct SphereTables {
  const SphereBenchRun& run;
  SphereResultIndex index;
  std::vector<const DatasetOutcome*> datasets;
  std::vector<SphereVariant> variants;
  bool has(SphereMethod m) const {
    return std::find(run.config.methods.begin(), run.config.methods.end(), m) != run.config.methods.end();
  }
};

// The run's own settings: image, cameras and frames, what the time budget shortened, the orbits.
void sphereSettings(std::ostringstream& md, const SphereBenchRun& run) {
  const SphereBenchConfig& c = run.config;
  md << "- Image " << c.width << "x" << c.height << ", vertical field of view " << printf1("%g", c.fovY)
     << " degrees. Per combination, each of an orbit's " << c.cameras << " cameras renders " << run.warmup
     << " warm-up frames and " << c.frames << (c.frames == 1 ? " timed frame" : " timed frames")
     << " (a frame being clear + draw + resolve or attachment copy, timed with timestamp queries); a cell is "
        "the median over the cameras of each camera's median. After each upload, frames of the first "
        "combination are rendered until their time settles, so that GPU clocks that fell to idle during the "
        "host's work are up again.\n";
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
  md << "- Orbits around the center of the spheres' bounds, looking at it, z up: **short** inside the bounds "
        "(an ellipse at half their extent along x and y, a quarter of the half height above the center), "
        "**long** outside them (20 degrees above the horizon, as far as keeps the bounds' enclosing sphere "
        "in "
        "the image). Every camera is listed in the JSON.\n";
}

// One table of an orbit: rows data set x layout x method, columns billboard x conservative, `cell` of each
// measured result.
template <class Cell>
void sphereTable(std::ostringstream& md, const SphereTables& t, Orbit orbit, Cell&& cell) {
  const SphereBenchConfig& c = t.run.config;
  md << "| data set | layout | method |";
  for (const SphereVariant& v : t.variants)
    md << " " << v.name() << " |";
  md << "\n| --- | --- | --- |";
  for (size_t k = 0; k < t.variants.size(); ++k)
    md << " ---: |";
  md << "\n";
  for (const DatasetOutcome* d : t.datasets)
    for (ParticleLayout layout : c.layouts)
      for (SphereMethod m : c.methods) {
        const bool billboards = sphereMethodTakesBillboards(m);
        std::vector<std::string> cells;
        bool any = false;
        for (size_t k = 0; k < t.variants.size(); ++k) {
          if (!billboards && k > 0) {
            cells.push_back("-");
            continue;
          }
          const SphereResult* r = t.index.find(d->dataset.name, layout, orbit, m, t.variants[k].billboard,
                                               t.variants[k].conservative);
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
}

// The long orbit's (or the first orbit's) effective bandwidth as a share of the copy bandwidth.
void sphereBandwidth(std::ostringstream& md, const SphereTables& t) {
  const SphereBenchConfig& c = t.run.config;
  if (c.orbits.empty()) return;
  const bool hasLong = std::find(c.orbits.begin(), c.orbits.end(), Orbit::Long) != c.orbits.end();
  const Orbit o = hasLong ? Orbit::Long : c.orbits.front();
  md << "## " << orbitName(o) << " orbit: effective bandwidth, % of copy bandwidth\n\n";
  md << "Effective bandwidth = particles x bytes per particle of the layout (";
  for (size_t k = 0; k < c.layouts.size(); ++k)
    md << (k ? ", " : "") << particleLayoutName(c.layouts[k]) << " "
       << particleLayoutInfo(c.layouts[k]).bytesPerParticle;
  md << ") / median time.\n\n";
  sphereTable(md, t, o, [](const SphereResult& r) { return printf1("%.0f%%", r.copyFraction * 100); });
}

// The benchmark target: sphere-compute against the fastest rasterization pipeline.
void sphereComputeAgainstFastest(std::ostringstream& md, const SphereTables& t) {
  const SphereBenchConfig& c = t.run.config;
  if (!t.has(SphereMethod::Compute) || c.methods.size() <= 1) return;
  md << "## sphere-compute against the fastest other method\n\n";
  md << "The fastest measured setting of each side (over layouts, billboards and conservative "
        "rasterization); speed-up = the other's time / sphere-compute's.\n\n";
  md << "| data set | orbit | sphere-compute | ms | fastest other | ms | speed-up |\n";
  md << "| --- | --- | --- | ---: | --- | ---: | ---: |\n";
  for (const DatasetOutcome* d : t.datasets)
    for (Orbit o : c.orbits) {
      const SphereResult* mine = fastest(
          t.run, d->dataset.name, o, [](const SphereResult& r) { return r.method == SphereMethod::Compute; });
      const SphereResult* other = fastest(
          t.run, d->dataset.name, o, [](const SphereResult& r) { return r.method != SphereMethod::Compute; });
      if (!mine && !other) continue;
      md << "| " << mdCell(d->dataset.label) << " | " << orbitName(o) << " | "
         << (mine ? particleLayoutName(mine->layout) : "n/a") << " | "
         << (mine ? formatMs(mine->medianMs) : "") << " | " << (other ? sphereSetting(*other) : "n/a")
         << " | " << (other ? formatMs(other->medianMs) : "") << " | "
         << (mine && other ? printf1("%.2fx", other->medianMs / mine->medianMs) : "") << " |\n";
    }
  md << "\n";
}

// The counters of one data set, orbit and layout: sphere-points' clamped spheres per billboard,
// sphere-compute's chunks and spills. False when nothing of them was measured.
bool sphereCounterCells(const SphereTables& t, const std::string& dataset, Orbit o, ParticleLayout layout,
                        std::vector<std::string>& cells) {
  auto count = [](const SphereResult* r, uint64_t SphereResult::*field) {
    return !r ? std::string() : r->ok() ? std::to_string(r->*field) : std::string("n/a");
  };
  bool any = false;
  if (t.has(SphereMethod::Points))
    for (SphereBillboard b : t.run.config.billboards) {
      const SphereResult* r = t.index.find(dataset, layout, o, SphereMethod::Points, b, false);
      any = any || r;
      cells.push_back(count(r, &SphereResult::clampedSpheres));
    }
  if (t.has(SphereMethod::Compute)) {
    const SphereResult* r = t.index.find(dataset, layout, o, SphereMethod::Compute);
    any = any || r;
    cells.push_back(count(r, &SphereResult::largeChunks));
    cells.push_back(count(r, &SphereResult::spilledSpheres));
    cells.push_back(!r || !r->ok() ? count(r, &SphereResult::visibleBatches)
                                   : std::to_string(r->visibleBatches) + " of " + std::to_string(r->batches));
  }
  return any;
}

// What sphere-points and sphere-compute counted in their frames.
void sphereCounters(std::ostringstream& md, const SphereTables& t) {
  const SphereBenchConfig& c = t.run.config;
  const bool points = t.has(SphereMethod::Points), compute = t.has(SphereMethod::Compute);
  if (!points && !compute) return;
  md << "## Per-frame counters (the most of an orbit's cameras)\n\n";
  md << "sphere-points: spheres larger than the device's largest point, drawn incomplete (per billboard, "
        "conservative off); sphere-compute: chunks of large spheres listed (16x16-pixel screen tiles of the "
        "largest boxes, bands of box rows of the others), large spheres "
        "that drew their chunks themselves (list full), and batches of 128 particles (stored in spatial "
        "order) that the occlusion test found visible, to be drawn first by the next frame.\n\n";
  md << "| data set | orbit | layout |";
  for (SphereBillboard b : c.billboards)
    if (points) md << " sphere-points clamped, " << sphereBillboardName(b) << " |";
  if (compute) md << " sphere-compute large chunks | spilled | visible batches |";
  md << "\n| --- | --- | --- |";
  for (size_t k = 0; k < (points ? c.billboards.size() : 0) + (compute ? 3 : 0); ++k)
    md << " ---: |";
  md << "\n";
  for (const DatasetOutcome* d : t.datasets)
    for (Orbit o : c.orbits)
      for (ParticleLayout layout : c.layouts) {
        std::vector<std::string> cells;
        if (!sphereCounterCells(t, d->dataset.name, o, layout, cells)) continue;
        md << "| " << mdCell(d->dataset.label) << " | " << orbitName(o) << " | " << particleLayoutName(layout)
           << " |";
        for (const std::string& text : cells)
          md << " " << text << " |";
        md << "\n";
      }
  md << "\n";
}

} // namespace

std::string sphereMarkdownReport(const SphereBenchRun& run, const ReportInfo& info) {
  const SphereTables tables{run, SphereResultIndex(run), measuredDatasets(run.datasets),
                            sphereVariants(run.config)};
  std::ostringstream md;
  markdownHeader(md, info, run.device, run.deviceLocalBytes, run.copy, run.stopped);
  sphereSettings(md, run);
  markdownFooter(md, info, run.seconds);
  for (Orbit o : run.config.orbits) {
    md << "## " << orbitName(o) << " orbit: median GPU time per frame, ms\n\n";
    md << "Methods that rasterize no billboards (sphere-compute) have one time, in the first column.\n\n";
    sphereTable(md, tables, o, [](const SphereResult& r) { return formatMs(r.medianMs); });
  }
  sphereBandwidth(md, tables);
  sphereComputeAgainstFastest(md, tables);
  sphereCounters(md, tables);
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

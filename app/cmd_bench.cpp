// pointrast bench FILE|SCENE... | --suite paper2021: the method x order x view matrix, timed on the GPU;
// --suite spheres2023: the sphere method x layout x billboard x conservative x orbit matrix; --suite lod:
// the LOD method's sweeps and streaming on octrees from the octree cache (bench/octree_cache.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <unistd.h>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "bench/lod_report.h"
#include "bench/lod_suite.h"
#include "bench/octree_cache.h"
#include "bench/report.h"
#include "bench/runner.h"
#include "bench/sphere_runner.h"
#include "bench/suites.h"
#include "bench/vr_report.h"
#include "bench/vr_suite.h"
#include "cli_util.h"
#include "cloud/generate.h"
#include "commands.h"
#include "distributed.h"
#include "gpu/context.h"
#include "input.h"
#include "io/format_table.h"
#include "mpi/mpi_job.h"
#include "render/spheres/sphere_renderer.h"

namespace pointrast::app {

namespace {

const std::vector<Order> kAllOrders = {Order::Original, Order::Morton, Order::Shuffled,
                                       Order::ShuffledMorton};

struct BenchArgs {
  std::vector<std::string> inputs;
  std::string suite, methods = "all", orders = "all", views = "all", points = "1M", copySize = "1G";
  std::string out, name, datasets = "all";
  // Octree methods and the lod suite: the octree cache, the streaming run's flight frames and jumps.
  std::string octreeCache;
  uint32_t flightFrames = bench::LodSuiteConfig{}.flightFrames, jumps = bench::LodSuiteConfig{}.jumps;
  // Sphere suites: the layouts, billboards, conservative settings and orbits measured, cameras per orbit.
  std::string layouts = "all", billboards = "all", conservative = "all", orbits = "all";
  uint32_t cameras = 10;
  double scale = 1.0, fov = 60;
  double budget = 2.0;    // --budget: GPU seconds per combination
  double timeLimit = 0.0; // --time-limit: wall seconds before no further combination starts
  uint32_t width = 1920, height = 1080, frames = 50;
  uint64_t seed = 1;
  std::optional<uint32_t> device;
  bool json = false, quiet = false;
  bool scaleGiven = false, pointsGiven = false;
  // Options given on the command line (a suite brings its own methods, orders, views and image size).
  bool methodsGiven = false, ordersGiven = false, viewsGiven = false, widthGiven = false, heightGiven = false;
  bool framesGiven = false, sphereOptionsGiven = false, streamOptionsGiven = false, datasetsGiven = false;
};

// Timed frames per camera of the sphere suites unless --frames says otherwise: 5 x 10 cameras = 50 frames
// per combination, as many as the point suites time.
constexpr uint32_t kSphereSuiteFrames = 5;

double timeLimitSeconds(const BenchArgs& a) {
  if (!(a.timeLimit >= 0) || !std::isfinite(a.timeLimit))
    throw InputError("--time-limit must be 0 (no limit) or a positive number of seconds");
  return a.timeLimit;
}

double budgetSeconds(const BenchArgs& a) {
  if (!(a.budget >= 0) || !std::isfinite(a.budget))
    throw InputError("--budget must be 0 (no limit) or a positive number of seconds");
  return a.budget;
}

// "a,b" -> {"a", "b"}, or every choice for "all"; each name parsed (InputError names the choices),
// duplicates dropped, first occurrence kept.
template <class T, class Parse>
std::vector<T> parseList(const std::string& text, const std::string& option, const std::vector<T>& all,
                         Parse parse) {
  if (text == "all") return all;
  std::vector<T> out;
  size_t at = 0;
  while (at <= text.size()) {
    size_t comma = text.find(',', at);
    std::string item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    if (item.empty())
      throw InputError(option + " '" + text + "': empty item; give names separated by commas, or all");
    T value = parse(item);
    if (std::find(out.begin(), out.end(), value) == out.end()) out.push_back(value);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  return out;
}

std::vector<bench::Dataset> inputDatasets(const BenchArgs& a) {
  std::vector<std::string> inputs = a.inputs;
  if (inputs.empty()) inputs.push_back(kDemoScene);
  uint64_t points = a.inputs.empty() ? kDemoPoints : parseCount(a.points, "--points");
  std::vector<bench::Dataset> out;
  for (const std::string& input : inputs) {
    bench::Dataset d;
    d.source = input;
    d.seed = a.seed;
    if (pathExists(input)) {
      d.file = true;
      d.name = std::filesystem::path(input).stem().string();
      d.label = std::filesystem::path(input).filename().string();
    } else if (isSceneName(input)) {
      if (points == 0) throw InputError("--points must be at least 1");
      d.points = points;
      d.name = input + "-" + bench::shortCount(points);
      d.label = d.name;
    } else {
      throw InputError(input + ": no such file, and not a scene name (terrain, tls)");
    }
    for (const bench::Dataset& other : out)
      if (other.name == d.name) throw InputError(input + ": given twice");
    out.push_back(d);
  }
  return out;
}

// Notes and one line per result on stderr; on a terminal each result line replaces the last, so the screen
// shows where the run is. A skipped data set or layout is said even when quiet.
class ProgressLines {
public:
  explicit ProgressLines(bool quiet) : quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0) {}
  void note(const std::string& line) {
    if (quiet_ && line.find("skipped") == std::string::npos) return;
    end();
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  void result(size_t done, size_t total, const std::string& what) {
    if (quiet_) return;
    std::fprintf(stderr, "%s[%zu/%zu] %s%s", tty_ ? "\r\033[K" : "", done, total, what.c_str(),
                 tty_ ? "" : "\n");
    open_ = tty_;
    std::fflush(stderr);
  }
  void end() {
    if (open_) std::fprintf(stderr, "\n");
    open_ = false;
  }

private:
  bool quiet_, tty_, open_ = false;
};

void printJsonLine(nlohmann::json j, const gpu::Context& context) {
  j["device"] = context.info().name;
  j["device_type"] = context.info().typeName;
  std::printf("%s\n", jsonText(j).c_str());
  std::fflush(stdout);
}

std::filesystem::path reportDir(const BenchArgs& a, const gpu::Context& context) {
  return a.out.empty() ? std::filesystem::path("bench/results") / bench::sanitizeName(context.info().name)
                       : std::filesystem::path(a.out);
}

// What every run checks at its end: validation errors, and that something was measured at all.
void checkRun(const gpu::Context& context, const std::vector<bench::DatasetOutcome>& datasets) {
  if (context.validationErrors() > 0)
    throw InternalError("the Vulkan validation layer reported " + std::to_string(context.validationErrors()) +
                        " error(s), above; no report was written");
  bool measured = false;
  std::string skipped;
  for (const bench::DatasetOutcome& d : datasets) {
    measured = measured || !d.skipped;
    if (d.skipped) skipped += (skipped.empty() ? "" : "; ") + d.dataset.label + " " + d.reason;
  }
  if (!measured) throw InputError("nothing was measured: " + skipped);
}

// The run's last words: the files written, and for a run a device fault ended, the fault as the one
// error line (exit 1) after the reports that keep what was measured before it.
void printWritten(const BenchArgs& a, const bench::RunRecord& run, size_t results,
                  const bench::WrittenFiles& files) {
  if (!(a.quiet && a.json))
    std::fprintf(a.json ? stderr : stdout, "%zu results in %.1f s; wrote %s, %s, %s\n", results, run.seconds,
                 files.json.string().c_str(), files.markdown.string().c_str(), files.svg.string().c_str());
  if (run.faulted)
    throw DeviceFault(run.stopped + "; " + files.json.string() + " holds what was measured before it");
}

gpu::ContextOptions contextOptions(const BenchArgs& a) {
  gpu::ContextOptions options;
  options.deviceIndex = a.device;
  options.announce = !a.quiet;
  return options;
}

bench::ReportInfo suiteReportInfo(const BenchArgs& a) {
  bench::ReportInfo info;
  info.name = a.suite;
  info.title = a.suite;
  if (a.scale != 1.0) {
    char text[64];
    std::snprintf(text, sizeof text, "%g", a.scale);
    info.name += std::string("-scale") + text;
    info.title += std::string(" (scale ") + text + ")";
  }
  if (!a.name.empty()) info.name = a.name;
  info.commandLine = commandLine("pointrast bench");
  info.date = bench::utcNow();
  return info;
}

bool parseOnOff(const std::string& item) {
  if (item == "off") return false;
  if (item == "on") return true;
  throw InputError("--conservative '" + item + "': choose off, on, or all");
}

// --datasets: the suite's data sets named (by the paper's name, "aerial1g", or the stand-in's,
// "aerial1g-like"), in the suite's order.
std::vector<bench::Dataset> pickDatasets(const BenchArgs& a, std::vector<bench::Dataset> all) {
  if (!a.datasetsGiven || a.datasets == "all") return all;
  auto baseName = [](const std::string& name) {
    const std::string like = "-like";
    return name.size() > like.size() && name.ends_with(like) ? name.substr(0, name.size() - like.size())
                                                             : name;
  };
  std::string names;
  for (const bench::Dataset& d : all)
    names += (names.empty() ? "" : ", ") + baseName(d.name);
  const std::vector<std::string> wanted =
      parseList(a.datasets, "--datasets", std::vector<std::string>{}, [&](const std::string& item) {
        for (const bench::Dataset& d : all)
          if (item == d.name || item == baseName(d.name)) return d.name;
        throw InputError("--datasets: '" + item + "' is no data set of suite " + a.suite + " (" + names +
                         ")");
      });
  std::vector<bench::Dataset> out;
  for (const bench::Dataset& d : all)
    if (std::find(wanted.begin(), wanted.end(), d.name) != wanted.end()) out.push_back(d);
  return out;
}

// The octrees of the LOD methods: the cache folder of --octree-cache, built there when missing.
bench::OctreeProvider octreeProvider(const BenchArgs& a, ProgressLines& lines) {
  bench::OctreeCacheOptions options;
  options.dir = a.octreeCache.empty() ? bench::defaultOctreeCacheDir() : std::filesystem::path(a.octreeCache);
  options.progress = !a.quiet;
  options.onNote = [&lines](const std::string& line) { lines.note(line); };
  return bench::octreeCache(std::move(options));
}

// --suite spheres2023: particle stand-ins, sphere methods of the method table.
int runSphereSuite(const BenchArgs& a) {
  if (!a.inputs.empty())
    throw InputError("--suite " + a.suite + " generates its data sets; it takes no INPUT (" +
                     a.inputs.front() + ")");
  if (a.ordersGiven || a.viewsGiven)
    throw InputError("--orders and --views apply to the point benchmarks; --suite " + a.suite +
                     " takes --orbits short,long");
  if (a.cameras == 0) throw InputError("--cameras must be at least 1");
  bench::SphereBenchConfig config;
  config.datasets = pickDatasets(a, bench::sphereSuiteDatasets(a.suite, a.scale, a.seed));
  std::vector<SphereMethod> allMethods;
  for (const SphereMethodInfo& m : sphereMethodTable())
    allMethods.push_back(m.method);
  config.methods = parseList(a.methods, "--methods", allMethods, parseSphereMethod);
  std::vector<ParticleLayout> allLayouts;
  for (const ParticleLayoutInfo& l : particleLayoutTable())
    allLayouts.push_back(l.layout);
  config.layouts = parseList(a.layouts, "--layouts", allLayouts, parseParticleLayout);
  config.billboards = parseList(
      a.billboards, "--billboards",
      std::vector<SphereBillboard>{SphereBillboard::Screen, SphereBillboard::Camera}, parseSphereBillboard);
  config.conservative =
      parseList(a.conservative, "--conservative", std::vector<bool>{false, true}, parseOnOff);
  config.orbits = parseList(a.orbits, "--orbits",
                            std::vector<bench::Orbit>(bench::allOrbits().begin(), bench::allOrbits().end()),
                            bench::parseOrbit);
  config.cameras = a.cameras;
  config.width = a.width;
  config.height = a.height;
  config.frames = a.framesGiven ? a.frames : kSphereSuiteFrames;
  config.secondsPerCombination = budgetSeconds(a);
  config.timeLimitSeconds = timeLimitSeconds(a);
  config.fovY = a.fov;
  config.copyBytes = parseCount(a.copySize, "--copy-size");
  if (config.copyBytes == 0) throw InputError("--copy-size must be at least 1");
  config.progress = !a.quiet;
  const bench::ReportInfo info = suiteReportInfo(a);

  gpu::Context context(contextOptions(a));
  ProgressLines lines(a.quiet);
  bench::SphereBenchCallbacks callbacks;
  callbacks.onNote = [&](const std::string& line) { lines.note(line); };
  callbacks.onResult = [&](const bench::SphereBenchRun& run, const bench::SphereResult& r, size_t done,
                           size_t total) {
    if (a.json) printJsonLine(bench::sphereResultJson(run, r), context);
    std::string what = r.dataset + " / " + particleLayoutName(r.layout) + " / " + bench::orbitName(r.orbit) +
                       " / " + sphereMethodName(r.method);
    if (r.billboards())
      what +=
          std::string(" / ") + sphereBillboardName(r.billboard) + (r.conservative ? ", conservative" : "");
    lines.result(done, total,
                 what + ": " + (r.ok() ? bench::formatMs(r.medianMs) + " ms" : std::string("n/a")));
  };
  bench::SphereBenchRun run = bench::runSphereBench(context, config, callbacks);
  lines.end();
  checkRun(context, run.datasets);
  bench::WrittenFiles files = bench::writeSphereReports(run, info, reportDir(a, context));
  printWritten(a, run, run.results.size(), files);
  return 0;
}

// --suite lod: the LOD method's sweeps (point budget, --min-node-px) and streaming on the stand-ins' octrees.
int runLodSuite(const BenchArgs& a) {
  if (a.ordersGiven)
    throw InputError(
        "--orders do not apply to --suite lod: an octree is the same whatever the points' order");
  bench::LodSuiteConfig config;
  config.datasets = pickDatasets(a, bench::suiteDatasets(a.suite, a.scale, a.seed, a.inputs));
  const bench::SuiteDefaults defaults = bench::suiteDefaults(a.suite);
  if (a.methodsGiven && parseList(a.methods, "--methods", allMethods(), parseMethod) != defaults.methods)
    throw InputError("--suite lod measures the method lod; use --suite paper2022 --methods ... for others");
  if (a.viewsGiven) {
    std::vector<bench::View> all(bench::allViews().begin(), bench::allViews().end());
    config.views = parseList(a.views, "--views", all, bench::parseView);
  } else {
    config.views = defaults.views;
  }
  config.width = a.widthGiven ? a.width : defaults.width;
  config.height = a.heightGiven ? a.height : defaults.height;
  config.frames = a.framesGiven ? a.frames : config.frames;
  config.fovY = a.fov;
  // The budgets shrink with the data set, so that a smoke run still sweeps from coarse to complete.
  for (uint64_t& budget : config.pointBudgets)
    budget = std::max<uint64_t>(uint64_t(std::llround(double(budget) * a.scale)), 1);
  if (a.flightFrames == 0) throw InputError("--flight-frames must be at least 1");
  config.flightFrames = a.flightFrames;
  config.jumps = a.jumps;
  config.timeLimitSeconds = timeLimitSeconds(a);
  config.copyBytes = parseCount(a.copySize, "--copy-size");
  if (config.copyBytes == 0) throw InputError("--copy-size must be at least 1");
  config.progress = !a.quiet;
  const bench::ReportInfo info = suiteReportInfo(a);

  gpu::Context context(contextOptions(a));
  ProgressLines lines(a.quiet);
  config.octrees = octreeProvider(a, lines);
  bench::LodSuiteCallbacks callbacks;
  callbacks.onNote = [&](const std::string& line) { lines.note(line); };
  size_t done = 0;
  const size_t total = config.datasets.size() *
                       (config.views.size() * (config.pointBudgets.size() + config.minNodePx.size()) + 1);
  callbacks.onSweep = [&](const bench::LodSuiteRun&, const bench::LodSweepResult& r) {
    std::string what = r.dataset + " / " + bench::viewName(r.view) + " / min-node-px " +
                       bench::printf1("%g", r.minNodePx) + " / budget " +
                       (r.pointBudget ? bench::shortCount(r.pointBudget) : std::string("none"));
    lines.result(++done, total,
                 what + ": " + (r.ok() ? bench::formatMs(r.stats.medianMs) + " ms" : std::string("n/a")));
  };
  callbacks.onStream = [&](const bench::LodSuiteRun&, const bench::LodStreamResult& r) {
    if (a.json) printJsonLine(bench::lodStreamJson(r), context);
    uint32_t converged = 0;
    for (const bench::LodJumpResult& jump : r.jumps)
      converged += jump.converged ? 1 : 0;
    lines.result(++done, total,
                 r.dataset + " / streaming: " +
                     (r.ok()
                          ? std::to_string(r.flight.size()) + " flight frames, " + std::to_string(converged) +
                                " of " + std::to_string(r.jumps.size()) + " jumps converged"
                          : "n/a, " + r.reason));
  };
  bench::LodSuiteRun run = bench::runLodSuite(context, config, callbacks);
  lines.end();
  checkRun(context, run.datasets);
  bench::WrittenFiles files = bench::writeLodSuiteReports(run, info, reportDir(a, context));
  printWritten(a, run, run.sweeps.size() + run.streams.size(), files);
  return 0;
}

// --suite vr2022: the VR frame on the 529 M stand-in's octree, a stereo pass against two mono renders.
int runVrSuite(const BenchArgs& a) {
  if (a.ordersGiven || a.methodsGiven)
    throw InputError("--suite vr2022 measures its own configurations; --orders and --methods do not apply");
  bench::VrSuiteConfig config;
  config.datasets = pickDatasets(a, bench::suiteDatasets(a.suite, a.scale, a.seed, a.inputs));
  if (a.viewsGiven) {
    std::vector<bench::View> all(bench::allViews().begin(), bench::allViews().end());
    config.views = parseList(a.views, "--views", all, bench::parseView);
  }
  if (a.widthGiven) config.width = a.width;
  if (a.heightGiven) config.height = a.height;
  if (a.framesGiven) config.frames = a.frames;
  config.timeLimitSeconds = timeLimitSeconds(a);
  config.copyBytes = parseCount(a.copySize, "--copy-size");
  if (config.copyBytes == 0) throw InputError("--copy-size must be at least 1");
  config.progress = !a.quiet;
  const bench::ReportInfo info = suiteReportInfo(a);

  gpu::Context context(contextOptions(a));
  ProgressLines lines(a.quiet);
  config.octrees = octreeProvider(a, lines);
  bench::VrSuiteCallbacks callbacks;
  callbacks.onNote = [&](const std::string& line) { lines.note(line); };
  size_t done = 0;
  const size_t total = config.datasets.size() * config.views.size() * (2 * bench::vrCases().size() - 1);
  callbacks.onResult = [&](const bench::VrSuiteRun&, const bench::VrResult& r) {
    if (a.json) {
      nlohmann::json j = {{"suite", a.suite},
                          {"dataset", r.dataset},
                          {"view", bench::viewName(r.view)},
                          {"case", r.caseName},
                          {"pass", r.stereo ? "stereo" : "mono"},
                          {"status", r.status}};
      if (r.ok()) j["median_ms"] = r.medianMs;
      if (!r.reason.empty()) j["reason"] = r.reason;
      printJsonLine(j, context);
    }
    lines.result(++done, total,
                 r.dataset + " / " + bench::viewName(r.view) + " / " + r.caseName + " / " +
                     (r.stereo ? "stereo" : "two mono") + ": " +
                     (r.ok() ? bench::formatMs(r.medianMs) + " ms" : std::string("n/a")));
  };
  bench::VrSuiteRun run = bench::runVrSuite(context, config, callbacks);
  lines.end();
  checkRun(context, run.datasets);
  bench::WrittenFiles files = bench::writeVrSuiteReports(run, info, reportDir(a, context));
  printWritten(a, run, run.results.size(), files);
  return 0;
}

// `mpirun -np N pointrast bench FILE|SCENE` (docs/mpi.md): every rank loads its share of each data set and
// times its frames; after each combination the last frame is composited on rank 0, whose result carries
// every rank's time (the slowest is the job's) and the composite's cost. Closest-point methods that draw a
// loaded cloud only, no suites, no time limit: every rank measures the same combinations.
bench::BenchRanks benchRanks(gpu::Context& context, const std::vector<std::string>& devices) {
  bench::BenchRanks ranks;
  ranks.loadShare = [](const bench::Dataset& d, bool progress) {
    InputSpec spec;
    spec.source = d.source;
    spec.points = d.points;
    spec.seed = d.seed;
    spec.progress = progress;
    PointCloud cloud = loadShare(spec);
    // As loadDataset: the display colors decided once (rank 0's choice for every rank), attributes dropped.
    bench::keepDisplayColorsOnly(cloud, agreeColors(displayColorMode(cloud)));
    return cloud;
  };
  ranks.any = [](bool mine) { return mpi::Job::get().sumOf(mine ? 1 : 0) > 0; };
  ranks.sum = [](uint64_t mine) { return mpi::Job::get().sumOf(mine); };
  ranks.composite = [&context, devices](Renderer& renderer, const Camera& camera, bench::Result& r) {
    mpi::Job& job = mpi::Job::get();
    // A combination some rank could not measure is not measured: rank 0 says which rank and why.
    if (job.sumOf(r.ok() ? 0 : 1) > 0) {
      const std::vector<std::string> reasons = job.gatherText(r.ok() ? "" : r.reason);
      for (size_t rank = 1; rank < reasons.size() && r.ok(); ++rank)
        if (!reasons[rank].empty()) {
          r.status = "unsupported";
          r.reason = "rank " + std::to_string(rank) + ": " + reasons[rank];
        }
      return;
    }
    CompositeStats composite;
    composite.devices = devices;
    RenderSettings settings;
    settings.method = r.method;
    compositeFrame(context, renderer, camera, settings, 0, r.stats, composite);
    if (!job.root()) return;
    r.stats.medianMs = composite.renderMs; // the job's frame is done when the slowest rank's is
    r.stats.points = composite.points;
    r.points = composite.points;
    r.stats.batch.reset(); // counted per rank
    r.ranks = compositeJson(composite);
  };
  return ranks;
}

// Refusals of a bench under mpirun, before anything is read; methods left at "all" become those that
// composite.
void checkBenchRanks(const BenchArgs& a, std::vector<Method>& methods) {
  std::vector<Method> kept;
  for (Method m : methods) {
    const MethodInfo& info = methodInfo(m);
    std::string why;
    if (info.layout == SceneLayout::Octree)
      why = std::string(info.name) + " draws an octree, which bench measures on one process";
    else if (!hasCanonicalWords(info))
      why = std::string(info.name) + " keeps no closest point per pixel, so ranks' frames cannot be "
                                     "composited";
    if (why.empty()) {
      kept.push_back(m);
    } else if (a.methodsGiven) {
      throw InputError(why + "; under mpirun bench measures the closest-point methods that draw a loaded "
                             "cloud (atomicmin, the batch methods)");
    }
  }
  methods = kept;
}

int runBench(const BenchArgs& a) {
  Progress::setEnabled(!a.quiet && mpi::Job::get().root());
  if (distributedRun() && !a.suite.empty())
    throw InputError(
        "--suite runs on one process; under mpirun bench measures the files and scenes it is given");
  if (distributedRun() && a.timeLimit > 0)
    throw InputError(
        "--time-limit applies to one process; under mpirun every rank measures every combination");
  if (a.frames == 0) throw InputError("--frames must be at least 1");
  if (a.width == 0 || a.height == 0) throw InputError("--width and --height must be at least 1");
  if (!(a.fov > 0 && a.fov < 180)) throw InputError("--fov must be between 0 and 180 degrees");
  if (a.scaleGiven && a.suite.empty())
    throw InputError("--scale applies to --suite only; use --points for a scene");
  if (a.pointsGiven && !a.suite.empty()) throw InputError("--points does not apply to --suite; use --scale");
  if (!a.name.empty() && (a.name.find('/') != std::string::npos || a.name == "." || a.name == ".."))
    throw InputError("--name '" + a.name + "': give a plain file name without '/'");
  if (a.datasetsGiven && a.suite.empty())
    throw InputError("--datasets picks data sets of a --suite; without one, name files or scenes");
  if (a.streamOptionsGiven && !bench::isLodSuite(a.suite))
    throw InputError("--flight-frames and --jumps apply to --suite lod");
  if (bench::isSphereSuite(a.suite)) return runSphereSuite(a);
  if (a.sphereOptionsGiven)
    throw InputError("--layouts, --billboards, --conservative, --orbits and --cameras apply to --suite "
                     "spheres2023");
  if (bench::isLodSuite(a.suite)) return runLodSuite(a);
  if (bench::isVrSuite(a.suite)) return runVrSuite(a);

  bench::BenchConfig config;
  config.methods = parseList(a.methods, "--methods", allMethods(), parseMethod);
  config.orders = parseList(a.orders, "--orders", kAllOrders, parseOrder);
  std::vector<bench::View> allViews(bench::allViews().begin(), bench::allViews().end());
  config.views = parseList(a.views, "--views", allViews, bench::parseView);
  config.width = a.width;
  config.height = a.height;
  config.frames = a.frames;
  config.secondsPerCombination = budgetSeconds(a);
  config.timeLimitSeconds = timeLimitSeconds(a);
  config.fovY = a.fov;
  config.orderSeed = a.seed;
  config.copyBytes = parseCount(a.copySize, "--copy-size");
  if (config.copyBytes == 0) throw InputError("--copy-size must be at least 1");
  config.progress = !a.quiet;

  bench::ReportInfo info;
  if (!a.suite.empty()) {
    config.datasets = pickDatasets(a, bench::suiteDatasets(a.suite, a.scale, a.seed, a.inputs));
    const bench::SuiteDefaults defaults = bench::suiteDefaults(a.suite);
    if (!a.methodsGiven && !defaults.methods.empty()) config.methods = defaults.methods;
    if (!a.ordersGiven && !defaults.orders.empty()) config.orders = defaults.orders;
    if (!a.viewsGiven && !defaults.views.empty()) config.views = defaults.views;
    if (!a.widthGiven) config.width = defaults.width;
    if (!a.heightGiven) config.height = defaults.height;
    // Orders or views given on the command line apply to every data set of the suite.
    for (bench::Dataset& d : config.datasets) {
      if (a.ordersGiven) d.orders.clear();
      if (a.viewsGiven) d.views.clear();
    }
    info = suiteReportInfo(a);
  } else {
    config.datasets = inputDatasets(a);
    for (const bench::Dataset& d : config.datasets)
      info.name += (info.name.empty() ? "" : "_") + d.name;
    info.title = info.name;
  }
  if (!a.name.empty()) info.name = a.name;
  info.commandLine = commandLine("pointrast bench");
  info.date = bench::utcNow();

  const bool distributed = distributedRun();
  if (distributed) checkBenchRanks(a, config.methods);
  gpu::ContextOptions device = contextOptions(a);
  if (distributed) chooseRankDevice(device);
  gpu::Context context(device);
  const bool root = mpi::Job::get().root();
  if (distributed) {
    config.ranks = benchRanks(context, announceRanks(context, a.quiet));
    config.progress = config.progress && root;
  }
  ProgressLines lines(a.quiet || !root);
  // The cache folder is only looked at when a method draws octrees.
  if (std::any_of(config.methods.begin(), config.methods.end(),
                  [](Method m) { return methodInfo(m).layout == SceneLayout::Octree; }))
    config.octrees = octreeProvider(a, lines);
  bench::BenchCallbacks callbacks;
  callbacks.onNote = [&](const std::string& line) { lines.note(line); };
  callbacks.onResult = [&](const bench::BenchRun& run, const bench::Result& r, size_t done, size_t total) {
    if (!root) return;
    if (a.json) printJsonLine(bench::resultJson(run, r), context);
    lines.result(done, total,
                 r.dataset + " / " + orderName(r.order) + " / " + bench::viewName(r.view) + " / " +
                     methodName(r.method) + ": " +
                     (r.ok() ? bench::formatMs(r.stats.medianMs) + " ms" : std::string("n/a")));
  };
  bench::BenchRun run = bench::runBench(context, config, callbacks);
  lines.end();
  if (distributed) {
    // Every rank's validation errors count, and only rank 0 writes the reports.
    if (const uint64_t errors = mpi::Job::get().sumOf(context.validationErrors()); errors > 0)
      throw InternalError("the Vulkan validation layer reported " + std::to_string(errors) +
                          " error(s) on the ranks, above; no report was written");
  }
  checkRun(context, run.datasets); // alike on every rank: the data sets skipped are agreed
  if (distributed && !root) {
    mpi::Job::get().close();
    return 0;
  }
  bench::WrittenFiles files = bench::writeReports(run, info, reportDir(a, context));
  printWritten(a, run, run.results.size(), files);
  if (distributed) mpi::Job::get().close();
  return 0;
}

// `bench --help`'s text after the options: what is timed and reported, each suite, examples.
std::string benchFooter() {
  const std::string text =
      "\nFor each data set, order, view and method: a warm-up (a tenth of --frames, at least 2), then "
      "--frames\n"
      "frames timed with timestamp queries (clear + render + resolve): median, min, max ms, points/s, and "
      "the\n"
      "effective bandwidth (points x bytes of point data the method reads / median time) as a fraction of "
      "the\n"
      "device's buffer-copy bandwidth, measured in the same run (bytes read + written per second).\n"
      "Views come from the bounds: overview (whole cloud in frame), closeup (eye at the center looking "
      "along\n"
      "+x: most points outside the frustum), outside (eye beyond the cloud looking away: no point in "
      "frame).\n"
      "Writes NAME.json, NAME.md (tables like Table 1 of the 2021 paper) and NAME.svg to --out, by default\n"
      "bench/results/<device>/. Without INPUT, the demo scene (terrain, 1 M points).\n\n"
      "--suite paper2021 generates stand-ins for the 2021 paper's data sets at its sizes (banyunibo 4 M "
      "tls,\n"
      "eclepens 47 M terrain, retz 145 M terrain, endeavor 796 M tls) and times, at 1920x1080, every order\n"
      "and view with the methods that draw uploaded points one by one:\n  " +
      methodNameList(bench::suiteDefaults("paper2021").methods) +
      ".\nIt states the memory each data set needs and skips what does not fit. --scale 0.001 shrinks every "
      "size\n"
      "(4 k .. 796 k points) for a quick smoke run; NAME=PATH arguments replace a stand-in by a file.\n"
      "--suite paper2022 stands in for the 2022 paper (Software Rasterization of 2 Billion Points): scan69m\n"
      "(tls, 69 M), aerial279m (terrain, 279 M), scan529m (tls, 529 M, overview and closeup) and aerial1g\n"
      "(terrain, 1,000 M) in Morton order, plus tls-order (tls, 100 M) in scan (original) and Morton order,\n"
      "overview and closeup, at 2560x1140, with the methods\n  " +
      methodNameList(bench::suiteDefaults("paper2022").methods) +
      ".\nIts report adds the batch statistics of the paper's Table 2 (batches and points "
      "processed/rendered,\n"
      "points per coordinate precision) and the LOD half of it (nodes and points selected, processed,\n"
      "rendered; the speed-up over batch-prefetch). Each data set is uploaded once per scene layout its\n"
      "methods read (float and batched, 16 B/point each); the memory estimate counts both. --methods,\n"
      "--orders, --views, --width and --height override the suite's; --datasets aerial1g,... measures only\n"
      "the data sets named.\n\n"
      "The LOD methods draw each data set's octree (Potree 2.0), built once from its points with the octree\n"
      "builder of `pointrast lod` (in memory, on all cores) into the octree cache (--octree-cache, by\n"
      "default ~/.cache/pointrast/octrees) and reused by later runs and by the other suite: KEY/ is the\n"
      "octree of the data set, size and seed KEY names, KEY.json its build's time and phases, which the\n"
      "reports give whether the octree was built or reused. A damaged entry is built again. The 1,000 M\n"
      "stand-in's octree takes about 18 GB of disk, and its build about 56 GB of memory beside the "
      "points.\n\n"
      "--suite lod measures the method lod on the octree of aerial1g (the 1,000 M stand-in of paper2022,\n"
      "the same octree) at 2560x1140: the full-detail frame time against the point budget (1 M .. 300 M,\n"
      "times --scale) and against --min-node-px (1000 .. 10), from the overview and the closeup; then\n"
      "streaming with a GPU node cache of an eighth of the octree: --flight-frames frames (600) of a\n"
      "flight low across the cloud and --jumps jumps (8) between far-apart views, each frame one viewer\n"
      "frame paced at 60 Hz, with the octree's files dropped from the page cache first where the system\n"
      "allows. It reports each frame's GPU and wall time against 60 fps, the frames until each jump\n"
      "converges (target: 30) and the rate nodes stream from disk. --views, --frames, --width and --height\n"
      "override the suite's.\n\n"
      "--suite vr2022 measures the VR frame of the 2022 paper on the octree of scan529m (tls, 529 M, the\n"
      "octree cache's, shared with paper2022): both eyes at 2478x2740 each, lod-hqs, foveated LOD (100 px "
      "in\n"
      "the fovea, 300 px at the corners), dilation, parallel eyes 6.4 cm apart, from the closeup and\n"
      "overview views; each configuration as one stereo pass and as two mono renders of the same eyes.\n"
      "--views, --frames, --width and --height (each eye's) override the suite's.\n\n"
      "--suite spheres2023 stands in for the particle data sets of \"Efficient Sphere Rendering Revisited\"\n"
      "(2023) with generated particle scenes at the sizes of its data sets: laser (particles-laser, 306 "
      "M:\n"
      "laser ablation, a crystal slab with a crater and ejected clusters), riemann (particles-block, 4 M: a\n"
      "shock tube, dense block between vapor regions), drop (particles-drops, 30 M) and fluid\n"
      "(particles-drops, 200 M: droplets and filaments in vapor). It times every sphere method of the "
      "method\n"
      "table (`pointrast render --help`) x layout (soa8, vec4x2, aos, xyz where the set allows: the\n"
      "generated sets have per-particle colors, so xyz is skipped) x billboard (screen, camera) x\n"
      "conservative rasterization (off, on where the device has it) for the methods that rasterize\n"
      "billboards, from two orbits of --cameras cameras (10) around the center of the bounds: short (inside\n"
      "the bounds) and long (outside, everything in frame). Per camera a warm-up and --frames timed frames\n"
      "(default 5 here); a result is the median over the orbit's cameras of each camera's median. Its\n"
      "report adds sphere-compute against the fastest other method. --methods, --layouts, --billboards,\n"
      "--conservative off,on and --orbits short,long pick parts of the matrix.\n\n"
      "Under mpirun (one rank per GPU, docs/mpi.md) every rank times its share of each data set, the last\n"
      "frame of each combination is composited on rank 0, and each result reports every rank's time and\n"
      "points and the composite's cost (the \"mpi\" object of --json, a table of ranks in NAME.md); the\n"
      "slowest rank's time is the result's. The closest-point methods that draw a loaded cloud only; no\n"
      "--suite, no --time-limit.\n\n"
      "Examples:\n"
      "  pointrast bench terrain --points 10M --methods atomicmin,earlyz --orders original,morton\n"
      "  mpirun -np 2 pointrast bench terrain --points 2G --methods atomicmin,batch-prefetch --json\n"
      "  pointrast bench autzen.las --views overview --frames 100 --json\n"
      "  pointrast bench --suite paper2021\n"
      "  pointrast bench --suite paper2021 --scale 0.001 --frames 5 --out /tmp/smoke\n"
      "  pointrast bench --suite paper2021 retz=/data/retz.las\n"
      "  pointrast bench --suite paper2022\n"
      "  pointrast bench --suite paper2022 --scale 0.001 --frames 5 --out /tmp/smoke\n"
      "  pointrast bench --suite paper2022 --datasets aerial1g --methods batch-prefetch,lod,lod-hqs\n"
      "  pointrast bench --suite lod --octree-cache /scratch/octrees\n"
      "  pointrast bench --suite lod --scale 0.001 --frames 2 --flight-frames 60 --jumps 2 --out /tmp/smoke\n"
      "  pointrast bench --suite vr2022 --octree-cache /scratch/octrees\n"
      "  pointrast bench --suite spheres2023\n"
      "  pointrast bench --suite spheres2023 --scale 0.0001 --cameras 2 --frames 1 --out /tmp/smoke\n"
      "  pointrast bench --suite spheres2023 --methods sphere-compute,sphere-points --orbits long";
  return text;
}

// Options bind to members of the BenchArgs that the command's closure keeps alive with the app.
// What is measured: inputs, a suite and its data sets, the octree cache, the lod suite's streaming.
void addSuiteOptions(CLI::App& cmd, BenchArgs& a) {
  cmd.add_option("INPUT", a.inputs,
                 "Point cloud files (" + io::formatList(io::FormatUse::Cloud) +
                     ") or scene names (terrain, tls); with --suite, NAME=PATH");
  cmd.add_option("--suite", a.suite, "Run a named suite: paper2021, paper2022, lod, vr2022 or spheres2023");
  cmd.add_option("--datasets", a.datasets, "With --suite: its data sets to measure, comma-separated, or all")
      ->capture_default_str()
      ->each([&a](const std::string&) { a.datasetsGiven = true; });
  cmd.add_option("--octree-cache", a.octreeCache,
                 "Folder of the octrees the LOD methods draw, built there when missing (default: "
                 "~/.cache/pointrast/octrees)");
  auto streamOption = [&a](const std::string&) { a.streamOptionsGiven = true; };
  cmd.add_option("--flight-frames", a.flightFrames, "lod: frames of the streaming run's flight")
      ->capture_default_str()
      ->each(streamOption);
  cmd.add_option("--jumps", a.jumps, "lod: jumps between far-apart views after the flight")
      ->capture_default_str()
      ->each(streamOption);
  cmd.add_option("--scale", a.scale, "Multiply every size of the suite (e.g. 0.001 for a smoke run)")
      ->each([&a](const std::string&) { a.scaleGiven = true; });
}

// The matrix of a run (methods x orders x views), the image and how long a combination is timed.
void addMatrixOptions(CLI::App& cmd, BenchArgs& a) {
  cmd.add_option("--methods", a.methods, "Methods, comma-separated, or all (see `pointrast render --help`)")
      ->capture_default_str()
      ->each([&a](const std::string&) { a.methodsGiven = true; });
  cmd.add_option("--orders", a.orders, "original, morton, shuffled, shuffled-morton, or all")
      ->capture_default_str()
      ->each([&a](const std::string&) { a.ordersGiven = true; });
  cmd.add_option("--views", a.views, "overview, closeup, outside, or all")
      ->capture_default_str()
      ->each([&a](const std::string&) { a.viewsGiven = true; });
  cmd.add_option("--width", a.width, "Image width in pixels (paper2022: 2560)")
      ->capture_default_str()
      ->each([&a](const std::string&) { a.widthGiven = true; });
  cmd.add_option("--height", a.height, "Image height in pixels (paper2022: 1140)")
      ->capture_default_str()
      ->each([&a](const std::string&) { a.heightGiven = true; });
  cmd.add_option("--frames", a.frames,
                 "Timed frames per combination (spheres2023: per camera, default 5); the median is reported")
      ->capture_default_str()
      ->each([&a](const std::string&) { a.framesGiven = true; });
  cmd.add_option("--budget", a.budget,
                 "GPU seconds per combination: a method whose first frame shows that warm-up + --frames "
                 "would take longer is timed over as many frames as fit (at least 3 after 1 warm-up; "
                 "spheres2023: over all cameras, at least 1 per camera); the reports list them; 0 = always "
                 "--frames")
      ->capture_default_str();
  cmd.add_option("--time-limit", a.timeLimit,
                 "Wall seconds after which no further combination starts; the reports then hold what was "
                 "measured and say where the run stopped (0 = no limit)")
      ->capture_default_str();
}

// The sphere suite's matrix and cameras.
void addSphereSuiteOptions(CLI::App& cmd, BenchArgs& a) {
  auto sphereOption = [&a](const std::string&) { a.sphereOptionsGiven = true; };
  cmd.add_option("--layouts", a.layouts, "spheres2023: particle layouts soa8, vec4x2, aos, xyz, or all")
      ->capture_default_str()
      ->each(sphereOption);
  cmd.add_option("--billboards", a.billboards, "spheres2023: billboards screen, camera, or all")
      ->capture_default_str()
      ->each(sphereOption);
  cmd.add_option("--conservative", a.conservative,
                 "spheres2023: conservative rasterization off, on (where supported), or all")
      ->capture_default_str()
      ->each(sphereOption);
  cmd.add_option("--orbits", a.orbits, "spheres2023: camera orbits short (inside), long (outside), or all")
      ->capture_default_str()
      ->each(sphereOption);
  cmd.add_option("--cameras", a.cameras, "spheres2023: cameras per orbit")
      ->capture_default_str()
      ->each(sphereOption);
}

} // namespace

Command addBench(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  CLI::App* cmd =
      app.add_subcommand("bench", "Time every method x vertex order x view on the GPU; JSON, Markdown, SVG");
  cmd->footer(benchFooter());
  addSuiteOptions(*cmd, *a);
  addMatrixOptions(*cmd, *a);
  addSphereSuiteOptions(*cmd, *a);
  cmd->add_option("--fov", a->fov, "Vertical field of view in degrees")->capture_default_str();
  cmd->add_option("--points", a->points, "Points of generated scenes (e.g. 20k, 10M)")
      ->capture_default_str()
      ->each([a](const std::string&) { a->pointsGiven = true; });
  cmd->add_option("--seed", a->seed, "Seed for generated scenes and shuffled orders")->capture_default_str();
  cmd->add_option("--copy-size", a->copySize,
                  "Bytes per copy of the bandwidth measurement (clamped to the device)")
      ->capture_default_str();
  cmd->add_option("--out", a->out, "Folder for the reports (default: bench/results/<device>/)");
  cmd->add_option("--name", a->name,
                  "File name of the reports without extension (default: suite or data sets)");
  cmd->add_option("--device", a->device, "Vulkan device index (see `pointrast info --devices`)");
  cmd->add_flag("--json", a->json, "Print one JSON object per result on stdout");
  cmd->add_flag("-q,--quiet", a->quiet,
                "No progress, device or memory lines (skipped data sets are still said)");
  return [a] { return runBench(*a); };
}

} // namespace pointrast::app

#include "bench/vr_suite.h"

#include <chrono>
#include <limits>
#include <memory>
#include <optional>

#include "bench/lod_runner.h"
#include "io/format_table.h"
#include "render/lod/lod_scene.h"

namespace pointrast::bench {

namespace {

using Clock = std::chrono::steady_clock;

Bounds boundsOf(const lod::OctreeMetadata& meta) {
  return meta.bounds.empty() ? meta.cube : meta.bounds;
}

RenderSettings caseSettings(const VrSuiteConfig& config, const VrCase& c, uint32_t frames, uint32_t warmup) {
  RenderSettings s;
  s.method = parseMethod(c.method);
  s.frames = frames;
  s.warmup = warmup;
  s.minNodePx = config.minNodePx;
  s.foveation = config.foveation;
  s.foveation.enabled = c.foveated;
  s.post.dilate = c.dilate ? config.dilate : 0;
  s.stereo.separation = config.ipd;
  s.stereo.convergence = std::numeric_limits<double>::infinity(); // parallel eyes, as a headset renders
  return s;
}

// Both eyes in one stereo pass, or each eye by a mono render (the left alone for a one-eye case).
void measure(Renderer& stereo, Renderer& mono, lod::LodScene& scene, const Camera& head,
             const RenderSettings& settings, bool onePass, bool oneEye, VrResult& r) {
  if (onePass) {
    r.passes.push_back(stereo.render(scene, head, settings));
    r.medianMs = r.passes.back().medianMs;
    return;
  }
  const double aspect = double(mono.width()) / double(mono.height());
  for (Eye eye : {Eye::Left, Eye::Right}) {
    if (oneEye && eye == Eye::Right) break;
    r.passes.push_back(mono.render(scene, eyeCamera(head, settings.stereo, eye, aspect), settings));
    r.medianMs += r.passes.back().medianMs;
  }
}

void runDataset(gpu::Context& context, Renderer& stereo, Renderer& mono, const VrSuiteConfig& config,
                const Dataset& dataset, lod::NodeSource& source, VrSuiteRun& run,
                const VrSuiteCallbacks& callbacks, Clock::time_point start, size_t& done, size_t total) {
  lod::LodScene scene(context, source);
  const Bounds bounds = boundsOf(source.metadata());
  const double aspect = double(config.width) / double(config.height);
  settleClocks([&](uint32_t frames) {
    return stereo
        .render(scene, viewCamera(config.views.front(), bounds, aspect, config.fovY),
                caseSettings(config, vrCases().front(), frames, 0))
        .medianMs;
  });
  for (View view : config.views) {
    const Camera head = viewCamera(view, bounds, aspect, config.fovY);
    for (const VrCase& c : vrCases()) {
      for (bool onePass : {true, false}) {
        if (onePass && c.oneEye) continue;
        checkTimeLimit(start, config.timeLimitSeconds, done, total);
        VrResult r;
        r.dataset = dataset.name;
        r.view = view;
        r.caseName = c.name;
        r.stereo = onePass;
        r.camera = describeCamera(head);
        const RenderSettings settings = caseSettings(config, c, config.frames, run.warmup);
        measureGuarded(
            r, [&] { measure(stereo, mono, scene, head, settings, onePass, c.oneEye, r); },
            [&](const VrResult& faulted) { run.results.push_back(faulted); });
        run.results.push_back(r);
        ++done;
        if (callbacks.onResult) callbacks.onResult(run, run.results.back());
      }
    }
  }
}

} // namespace

const std::vector<VrCase>& vrCases() {
  static const std::vector<VrCase> cases = {
      {"vr frame", "lod-hqs", true, true, false},
      {"lod, no dilation", "lod", true, false, false},
      {"vr frame, no foveation", "lod-hqs", false, true, false},
      {"one eye", "lod-hqs", true, true, true},
  };
  return cases;
}

double stereoSpeedup(const VrSuiteRun& run, const VrResult& stereo) {
  if (!stereo.stereo || !stereo.ok()) return 1.0;
  for (const VrResult& r : run.results)
    if (!r.stereo && r.ok() && r.dataset == stereo.dataset && r.view == stereo.view &&
        r.caseName == stereo.caseName && stereo.medianMs > 0)
      return r.medianMs / stereo.medianMs;
  return 1.0;
}

VrSuiteRun runVrSuite(gpu::Context& context, const VrSuiteConfig& config, const VrSuiteCallbacks& callbacks) {
  const auto start = Clock::now();
  auto note = [&](const std::string& line) {
    if (callbacks.onNote) callbacks.onNote(line);
  };
  VrSuiteRun run;
  run.device = context.info();
  run.deviceLocalBytes = context.deviceLocalBytes();
  run.config = config;
  run.warmup = warmupFrames(config.frames);
  run.copy = gpu::measureCopy(context, config.copyBytes, config.copyRepeats);
  note(copyBandwidthText(run.copy));
  Renderer stereo(context, config.width, config.height, 2);
  Renderer mono(context, config.width, config.height);
  const size_t perDataset = config.views.size() * (2 * vrCases().size() - 1);
  const size_t total = config.datasets.size() * perDataset;
  size_t done = 0;
  try {
    for (const Dataset& d : config.datasets) {
      checkTimeLimit(start, config.timeLimitSeconds, done, total);
      DatasetOutcome outcome;
      outcome.dataset = d;
      std::optional<PointCloud> cloud;
      auto points = [&]() -> const PointCloud& {
        if (!cloud) cloud = loadDataset(d, config.progress);
        return *cloud;
      };
      std::unique_ptr<lod::NodeSource> source;
      DatasetOctree octree;
      try {
        if (!config.octrees) throw InputError("no octree: this run has no octree builder or cache");
        octree = config.octrees(octreeKey(d), points);
        source = io::openNodeSource(octree.path);
      } catch (const InputError& e) {
        outcome.skipped = true;
        outcome.reason = e.what();
      } catch (const UnsupportedError& e) {
        outcome.skipped = true;
        outcome.reason = e.what();
      }
      cloud.reset(); // the build's input: the octree is on disk now
      if (outcome.skipped) {
        note(d.label + ": skipped, " + outcome.reason);
        run.datasets.push_back(outcome);
        done += perDataset;
        continue;
      }
      outcome.points = source->metadata().pointCount;
      outcome.description = source->metadata().source + " (" + source->metadata().format + ")";
      run.datasets.push_back(outcome);
      run.octrees.emplace_back(d.name, octree);
      note(d.label + ": octree " + octree.path.string() +
           (octree.reused ? " (from the cache)" : " built in " + printf1("%.1f s", octree.buildSeconds)));
      try {
        runDataset(context, stereo, mono, config, d, *source, run, callbacks, start, done, total);
      } catch (const InputError& e) { // a damaged octree found while streaming
        note(d.label + ": stopped, " + e.what());
      } catch (const UnsupportedError& e) {
        note(d.label + ": stopped, " + e.what());
      }
    }
  } catch (const DeviceFault& e) {
    run.stopped = deviceFaultText(e);
    note("stopped: " + run.stopped);
  } catch (const TimeLimitReached& e) {
    run.stopped = e.what();
    note("stopped: " + run.stopped);
  }
  run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return run;
}

} // namespace pointrast::bench

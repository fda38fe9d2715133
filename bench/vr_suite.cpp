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
  const Note note = [&](const std::string& line) {
    if (callbacks.onNote) callbacks.onNote(line);
  };
  VrSuiteRun run;
  run.config = config;
  run.warmup = warmupFrames(config.frames);
  runRecorded(context, run, config.copyBytes, config.copyRepeats, start, note, [&] {
    Renderer stereo(context, config.width, config.height, 2);
    Renderer mono(context, config.width, config.height);
    const size_t perDataset = config.views.size() * (2 * vrCases().size() - 1);
    const size_t total = config.datasets.size() * perDataset;
    size_t done = 0;
    for (const Dataset& d : config.datasets) {
      checkTimeLimit(start, config.timeLimitSeconds, done, total);
      DatasetOutcome outcome;
      auto [source, octree] = openDatasetOctree(d, config.octrees, config.progress, outcome, note);
      if (outcome.skipped) {
        run.datasets.push_back(outcome);
        done += perDataset;
        continue;
      }
      run.datasets.push_back(outcome);
      run.octrees.emplace_back(d.name, octree);
      measureDataset(d, note, [&] {
        runDataset(context, stereo, mono, config, d, *source, run, callbacks, start, done, total);
      });
    }
  });
  return run;
}

} // namespace pointrast::bench

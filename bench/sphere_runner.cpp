#include "bench/sphere_runner.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>

#include "base/error.h"
#include "cloud/particles_generate.h"
#include "gpu/timer.h"
#include "render/spheres/spheres.h"

namespace pointrast::bench {

namespace {

std::vector<SphereMethod> methodsOf(const SphereBenchConfig& config) {
  if (!config.methods.empty()) return config.methods;
  std::vector<SphereMethod> all;
  for (const SphereMethodInfo& m : sphereMethodTable())
    all.push_back(m.method);
  return all;
}

ParticleSet generate(const Dataset& d, uint64_t particles, bool progress) {
  ParticleGenerateOptions options;
  options.particles = particles;
  options.seed = d.seed;
  options.progress = progress;
  return generateParticles(parseParticleScene(d.source), options);
}

// The layouts of the configuration that hold the data set exactly, decided on a small sample of the same
// scene (a generator gives every size of a scene the same attributes: per-particle colors, one radius), so
// that what will be skipped is known before the set is generated. The others are said in `skipped`.
std::vector<ParticleLayout> layoutsHolding(const SphereBenchConfig& config, const Dataset& d,
                                           std::vector<std::string>& skipped) {
  const ParticleSet sample = generate(d, 1000, false);
  std::vector<ParticleLayout> held;
  for (ParticleLayout layout : config.layouts) {
    std::string why;
    if (layoutHolds(layout, sample, &why))
      held.push_back(layout);
    else
      skipped.push_back(d.label + ": layout " + particleLayoutName(layout) + " skipped: " + why);
  }
  return held;
}

} // namespace

MemoryEstimate estimateSphereMemory(const gpu::Context& context, uint64_t particles, uint32_t width,
                                    uint32_t height, const std::vector<ParticleLayout>& layouts,
                                    size_t methods) {
  uint64_t perParticle = 0;
  for (ParticleLayout layout : layouts)
    perParticle = std::max<uint64_t>(perParticle, particleLayoutInfo(layout).bytesPerParticle);
  MemoryEstimate m;
  const uint64_t pixels = uint64_t(width) * height;
  m.gpuBytes = particles * perParticle +
               pixels * (kSphereSharedBytesPerPixel + kSphereMethodBytesPerPixel * methods) +
               kSphereFixedBytes;
  m.hostBytes = particles * kSphereHostBytesPerParticle;
  if (context.info().software()) m.hostBytes += m.gpuBytes;
  m.gpuHave = context.deviceLocalBytes();
  m.hostHave = physicalMemory();
  return m;
}

std::vector<SphereResult> sphereCombinations(const SphereBenchConfig& config) {
  std::vector<SphereResult> combinations;
  for (SphereMethod method : methodsOf(config)) {
    SphereResult r;
    r.method = method;
    if (!sphereMethodTakesBillboards(method)) {
      combinations.push_back(r);
      continue;
    }
    for (SphereBillboard billboard : config.billboards)
      for (bool conservative : config.conservative) {
        r.billboard = billboard;
        r.conservative = conservative;
        combinations.push_back(r);
      }
  }
  return combinations;
}

namespace {

// Sizes every data set and decides its layouts before anything runs, so that what will be skipped is
// said up front. Returns the number of combinations the run will measure; layouts[k] are data set k's.
size_t sizeSphereDatasets(const gpu::Context& context, const SphereBenchConfig& config, size_t combinations,
                          SphereBenchRun& run, std::vector<std::vector<ParticleLayout>>& layouts,
                          const Note& note) {
  size_t total = 0;
  for (const Dataset& d : config.datasets) {
    DatasetOutcome outcome;
    outcome.dataset = d;
    outcome.points = d.points;
    std::vector<std::string> skipped;
    layouts.push_back(layoutsHolding(config, d, skipped));
    for (const std::string& line : skipped)
      note(line);
    run.skippedLayouts.insert(run.skippedLayouts.end(), skipped.begin(), skipped.end());
    outcome.memory = estimateSphereMemory(context, d.points, config.width, config.height, layouts.back(),
                                          run.config.methods.size());
    if (d.points == 0) {
      outcome.skipped = true;
      outcome.reason = "it has no particles";
    } else if (layouts.back().empty()) {
      outcome.skipped = true;
      outcome.reason = "none of the layouts asked for holds it";
    } else if (!outcome.memory.fits()) {
      outcome.skipped = true;
      outcome.reason = "it does not fit: " + outcome.memory.describe();
    }
    note(d.label + ": " + (outcome.skipped ? "skipped, " + outcome.reason : outcome.memory.describe()));
    if (!outcome.skipped) total += layouts.back().size() * config.orbits.size() * combinations;
    run.datasets.push_back(std::move(outcome));
  }
  return total;
}

// The cameras of every orbit around a data set, recorded in the run as describeCamera() gives them.
std::vector<std::vector<Camera>> orbitsOf(const SphereBenchConfig& config, const Dataset& d,
                                          const Bounds& bounds, SphereBenchRun& run) {
  const double aspect = double(config.width) / double(config.height);
  std::vector<std::vector<Camera>> cameras;
  for (Orbit orbit : config.orbits) {
    cameras.push_back(orbitCameras(orbit, bounds, aspect, config.fovY, config.cameras));
    SphereOrbitCameras described{d.name, orbit, {}};
    for (const Camera& c : cameras.back())
      described.cameras.push_back(describeCamera(c));
    run.cameras.push_back(described);
  }
  return cameras;
}

SphereSettings settingsOf(const SphereResult& c) {
  SphereSettings s;
  s.method = c.method;
  s.billboard = c.billboard;
  s.conservative = c.conservative;
  return s;
}

// Renders the first combination the device has until the GPU's clocks are up again after the host's work
// (settleClocks); what goes wrong is left to the combinations, which report it.
void settleFirst(gpu::Context& context, SphereRenderer& renderer, const GpuParticles& particles,
                 const std::vector<SphereResult>& combinations, const Camera& camera) {
  if (!settlesClocks(context)) return;
  for (const SphereResult& c : combinations) {
    SphereSettings settle = settingsOf(c);
    settle.warmup = 0;
    if (!SphereRenderer::supports(context, settle)) continue;
    try {
      settleClocks([&](uint32_t frames) {
        settle.frames = frames;
        return renderer.render(particles, camera, settle).medianMs;
      });
    } catch (const UnsupportedError&) {
    } catch (const InputError&) {
    }
    return;
  }
}

// Times one combination from every camera of its orbit. With a time budget, one frame of the first camera
// decides how many frames per camera it allows; a slow pipeline is then timed over fewer frames per camera,
// without warm-up (the probe warmed it), so the medians still cover every camera.
void timeSphereCombination(SphereRenderer& renderer, const GpuParticles& particles,
                           const std::vector<Camera>& cameras, const SphereBenchRun& run, SphereResult& r) {
  const SphereBenchConfig& config = run.config;
  SphereSettings settings = settingsOf(r);
  settings.frames = config.frames;
  settings.warmup = run.warmup;
  if (config.secondsPerCombination > 0 && !cameras.empty()) {
    SphereSettings probe = settings;
    probe.frames = 1;
    probe.warmup = 0;
    const double seconds = renderer.render(particles, cameras[0], probe).medianMs * 1e-3;
    settings.frames = budgetedFrames(config.frames, run.warmup, seconds,
                                     config.secondsPerCombination / double(cameras.size()), 1);
    if (settings.frames < config.frames) settings.warmup = 0;
    r.frames = settings.frames;
  }
  for (const Camera& camera : cameras) {
    const SphereStats stats = renderer.render(particles, camera, settings);
    r.cameraMs.push_back(stats.medianMs);
    r.clampedSpheres = std::max(r.clampedSpheres, stats.clampedSpheres);
    r.largeChunks = std::max(r.largeChunks, stats.largeChunks);
    r.spilledSpheres = std::max(r.spilledSpheres, stats.spilledSpheres);
    r.batches = stats.batches;
    r.visibleBatches = std::max(r.visibleBatches, stats.visibleBatches);
  }
}

// The median over the cameras and the rates against the run's copy bandwidth.
void deriveSphereRates(SphereResult& r, const gpu::CopyBandwidth& copy) {
  if (!r.ok() || r.cameraMs.empty()) return;
  r.medianMs = gpu::median(r.cameraMs);
  r.minMs = *std::min_element(r.cameraMs.begin(), r.cameraMs.end());
  r.maxMs = *std::max_element(r.cameraMs.begin(), r.cameraMs.end());
  if (!(r.medianMs > 0)) return;
  const double seconds = r.medianMs * 1e-3;
  r.particlesPerSecond = double(r.particles) / seconds;
  r.effectiveBytesPerSecond = double(r.particles) * r.bytesPerParticle / seconds;
  r.copyFraction = copy.bytesPerSecond > 0 ? r.effectiveBytesPerSecond / copy.bytesPerSecond : 0;
}

} // namespace

SphereBenchRun runSphereBench(gpu::Context& context, const SphereBenchConfig& config,
                              const SphereBenchCallbacks& callbacks) {
  const auto start = std::chrono::steady_clock::now();
  const Note note = [&](const std::string& line) {
    if (callbacks.onNote) callbacks.onNote(line);
  };
  SphereBenchRun run;
  run.config = config;
  run.config.methods = methodsOf(config);
  run.warmup = warmupFrames(config.frames);
  const std::vector<SphereResult> combinations = sphereCombinations(run.config);
  std::vector<std::vector<ParticleLayout>> layouts;
  const size_t total = sizeSphereDatasets(context, config, combinations.size(), run, layouts, note);
  runRecorded(context, run, config.copyBytes, config.copyRepeats, start, note, [&] {
    SphereRenderer renderer(context, config.width, config.height);
    size_t done = 0;
    auto record = [&](const SphereResult& r) {
      run.results.push_back(r);
      ++done;
      if (callbacks.onResult) callbacks.onResult(run, run.results.back(), done, total);
    };
    for (size_t k = 0; k < run.datasets.size(); ++k) {
      DatasetOutcome& outcome = run.datasets[k];
      if (outcome.skipped) continue;
      checkTimeLimit(start, config.timeLimitSeconds, done, total); // generating a set takes a while
      const Dataset& d = outcome.dataset;
      auto since = std::chrono::steady_clock::now();
      const ParticleSet set = generate(d, d.points, config.progress);
      outcome.points = set.size();
      outcome.description = set.source;
      note(d.label + ": " + set.source + " ready in " + printf1("%.1f s", secondsSince(since)));
      const std::vector<std::vector<Camera>> cameras = orbitsOf(config, d, sphereBounds(set), run);
      for (ParticleLayout layout : layouts[k]) {
        since = std::chrono::steady_clock::now();
        std::unique_ptr<GpuParticles> particles;
        std::string failure;
        try {
          ParticleUploadOptions upload;
          upload.layout = layout;
          upload.progress = config.progress;
          particles = std::make_unique<GpuParticles>(context, set, upload);
        } catch (const UnsupportedError& e) {
          failure = e.what(); // out of device memory after all: every combination says so
        }
        note(d.label + " / " + particleLayoutName(layout) + ": uploaded in " +
             printf1("%.1f s", secondsSince(since)));
        if (particles && !cameras.empty() && !cameras[0].empty())
          settleFirst(context, renderer, *particles, combinations, cameras[0][0]);
        for (size_t o = 0; o < config.orbits.size(); ++o) {
          for (SphereResult r : combinations) {
            checkTimeLimit(start, config.timeLimitSeconds, done, total);
            r.dataset = d.name;
            r.layout = layout;
            r.orbit = config.orbits[o];
            r.particles = set.size();
            r.frames = config.frames;
            r.bytesPerParticle = particleLayoutInfo(layout).bytesPerParticle;
            std::string why;
            if (!particles) {
              r.status = "unsupported";
              r.reason = failure;
            } else if (!SphereRenderer::supports(context, settingsOf(r), &why)) {
              r.status = "unsupported";
              r.reason = why;
            } else {
              measureGuarded(
                  r, [&] { timeSphereCombination(renderer, *particles, cameras[o], run, r); }, record);
            }
            deriveSphereRates(r, run.copy);
            record(r);
          }
        }
      }
    }
  });
  return run;
}

} // namespace pointrast::bench

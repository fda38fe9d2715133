#include "bench/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <unistd.h>

#include "base/error.h"
#include "base/parallel.h"
#include "bench/lod_runner.h"
#include "cloud/generate.h"
#include "io/reader.h"
#include "render/scene.h"

namespace pointrast::bench {

namespace {

// Points a data set will have, known before it is loaded: generated scenes have exactly the count
// asked for; files state theirs in the header (counted for XYZ). Not probeFile() where the header
// suffices: it reads every LAS color to tell the color depth.
uint64_t expectedPoints(const Dataset& d) {
  if (!d.file) return d.points;
  std::optional<uint64_t> stated = io::statedPointCount(d.source);
  return stated ? *stated : io::probeFile(d.source).pointCount;
}

const std::vector<Order>& ordersOf(const Dataset& d, const BenchConfig& c) {
  return d.orders.empty() ? c.orders : d.orders;
}
const std::vector<View>& viewsOf(const Dataset& d, const BenchConfig& c) {
  return d.views.empty() ? c.views : d.views;
}

} // namespace

std::string printf1(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string copyBandwidthText(const gpu::CopyBandwidth& copy) {
  char line[160];
  std::snprintf(line, sizeof line, "copy bandwidth: %.1f GB/s (read + write, %s copied, median of %d)",
                copy.bytesPerSecond * 1e-9, bytesText(copy.bytes).c_str(), copy.repeats);
  return line;
}

uint64_t physicalMemory() {
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : 0;
}

std::string deviceFaultText(const DeviceFault& fault) {
  return std::string(fault.what()) + "; the run stopped there, later combinations were not run";
}

void checkTimeLimit(std::chrono::steady_clock::time_point start, double limitSeconds, size_t done,
                    size_t total) {
  if (!(limitSeconds > 0)) return;
  const double seconds = secondsSince(start);
  if (seconds > limitSeconds)
    throw TimeLimitReached("time limit of " + printf1("%g", limitSeconds) + " s reached after " +
                           std::to_string(done) + " of " + std::to_string(total) +
                           " combinations; the rest were not run");
}

uint32_t warmupFrames(uint32_t frames) {
  return std::max(2u, frames / 10);
}

uint32_t budgetedFrames(uint32_t frames, uint32_t warmup, double probeSeconds, double budget,
                        uint32_t minFrames) {
  if (!(budget > 0) || !(probeSeconds > 0) || probeSeconds * double(warmup + frames) <= budget) return frames;
  const auto fit = uint32_t(std::min(std::floor(budget / probeSeconds + 1e-9), double(frames)));
  return std::max(std::min(minFrames, frames), fit);
}

std::string MemoryEstimate::describe() const {
  return "needs " + bytesText(gpuBytes) + " of GPU memory (device has " + bytesText(gpuHave) + ") and " +
         bytesText(hostBytes) + " of host memory (machine has " + bytesText(hostHave) + ")";
}

std::vector<SceneLayout> layoutsOf(const std::vector<Method>& methods) {
  std::vector<SceneLayout> layouts;
  for (SceneLayout layout : {SceneLayout::Float, SceneLayout::Batched})
    for (Method m : methods)
      if (methodInfo(m).layout == layout) {
        layouts.push_back(layout);
        break;
      }
  return layouts;
}

MemoryEstimate estimateMemory(const gpu::Context& context, uint64_t points, uint32_t width, uint32_t height,
                              const std::vector<Method>& methods) {
  MemoryEstimate m;
  m.gpuBytes = uint64_t(width) * height * kTargetBytesPerPixel;
  std::vector<SceneLayout> layouts = layoutsOf(methods);
  if (layouts.empty()) layouts.push_back(SceneLayout::Float);
  for (SceneLayout layout : layouts)
    m.gpuBytes += sceneBytes(layout, points);
  m.hostBytes = points * kHostBytesPerPoint;
  if (context.info().software()) m.hostBytes += m.gpuBytes;
  m.gpuHave = context.deviceLocalBytes();
  m.hostHave = physicalMemory();
  return m;
}

PointCloud loadDataset(const Dataset& dataset, bool progress) {
  if (!dataset.file) {
    GenerateOptions options;
    options.points = dataset.points;
    options.seed = dataset.seed;
    options.progress = progress;
    return generateScene(parseScene(dataset.source), options); // positions and RGB only already
  }
  io::ReadOptions options;
  options.progress = progress;
  PointCloud cloud = io::readCloud(dataset.source, options);
  // Decide the display colors once, from the whole cloud, and drop what rendering never reads: every
  // order then uploads the same colors from 16 B/point, and the reordered copy needs no attributes.
  keepDisplayColorsOnly(cloud, displayColorMode(cloud));
  return cloud;
}

void keepDisplayColorsOnly(PointCloud& cloud, const DisplayColorMode& mode) {
  std::vector<uint32_t> colors(cloud.size());
  displayColors(colors.data(), cloud, 0, cloud.size(), mode);
  cloud.colors = std::move(colors);
  cloud.intensity = {};
  cloud.classification = {};
  cloud.returnNumber = {};
  cloud.pointSourceId = {};
}

namespace {

// Sizes every data set before anything runs, so that what will be skipped is said up front. Returns the
// number of combinations the run will measure.
size_t sizeDatasets(const gpu::Context& context, const BenchConfig& config, BenchRun& run, const Note& note) {
  size_t total = 0;
  const size_t octrees = size_t(std::count_if(config.methods.begin(), config.methods.end(), [](Method m) {
    return methodInfo(m).layout == SceneLayout::Octree;
  }));
  for (const Dataset& d : config.datasets) {
    DatasetOutcome outcome;
    outcome.dataset = d;
    outcome.points = expectedPoints(d);
    outcome.memory = estimateMemory(context, outcome.points, config.width, config.height, config.methods);
    if (outcome.points == 0) {
      outcome.skipped = true;
      outcome.reason = "it has no points";
    } else if (!outcome.memory.fits()) {
      outcome.skipped = true;
      outcome.reason = "it does not fit: " + outcome.memory.describe();
    }
    note(d.label + ": " + (outcome.skipped ? "skipped, " + outcome.reason : outcome.memory.describe()));
    if (!outcome.skipped) // the LOD methods draw the data set's octree, once whatever the orders
      total += viewsOf(d, config).size() *
               (ordersOf(d, config).size() * (config.methods.size() - octrees) + octrees);
    run.datasets.push_back(std::move(outcome));
  }
  return total;
}

// One order of a data set on the GPU: a scene per layout the methods read (a suite mixing 2021 and batch
// methods holds both). A layout that did not fit after all says why, for every combination that reads it.
struct OrderScenes {
  std::map<SceneLayout, std::unique_ptr<GpuScene>> scenes;
  std::map<SceneLayout, std::string> failures;
  const GpuScene* find(SceneLayout layout) const {
    auto it = scenes.find(layout);
    return it == scenes.end() ? nullptr : it->second.get();
  }
};

OrderScenes uploadOrder(gpu::Context& context, const PointCloud& cloud, Order order,
                        const BenchConfig& config) {
  OrderScenes out;
  PointCloud ordered; // freed on return, before the GPU work
  if (order != Order::Original) {
    std::vector<uint64_t> permutation;
    computeOrder(permutation, cloud, order, config.orderSeed);
    ordered = orderedCopy(cloud, permutation);
  }
  for (SceneLayout layout : layoutsOf(config.methods)) {
    UploadOptions upload;
    upload.layout = layout;
    upload.progress = config.progress;
    try {
      out.scenes[layout] =
          std::make_unique<GpuScene>(context, order == Order::Original ? cloud : ordered, upload);
    } catch (const UnsupportedError& e) {
      out.failures[layout] = e.what(); // out of device memory after all
    }
  }
  return out;
}

} // namespace

void completeRates(Result& r, const gpu::CopyBandwidth& copy) {
  if (!r.ok() || !(r.stats.medianMs > 0)) return;
  const double seconds = r.stats.medianMs * 1e-3;
  r.pointsPerSecond = double(r.stats.points) / seconds;
  const double bytes =
      r.stats.batch ? double(r.stats.batch->bytesRead) : double(r.stats.points) * r.bytesPerPoint;
  r.effectiveBytesPerSecond = bytes / seconds;
  r.copyFraction = copy.bytesPerSecond > 0 ? r.effectiveBytesPerSecond / copy.bytesPerSecond : 0;
}

double secondsSince(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void settleWithFirst(const gpu::Context& context, std::span<const Method> methods,
                     const std::function<bool(Method)>& runs, const RenderFrames& render) {
  if (!settlesClocks(context)) return;
  for (Method method : methods) {
    if (!runs(method)) continue;
    try {
      settleClocks([&](uint32_t frames) {
        RenderSettings settle;
        settle.method = method;
        settle.frames = frames;
        settle.warmup = 0;
        return render(settle).medianMs;
      });
    } catch (const UnsupportedError&) {
    } catch (const InputError&) {
    }
    return;
  }
}

FrameStats timeFrames(Method method, const BenchRun& run, const RenderFrames& render) {
  const BenchConfig& config = run.config;
  RenderSettings settings;
  settings.method = method;
  settings.captureWords = config.ranks.has_value(); // the last frame's words go to the composite
  settings.frames = config.frames;
  settings.warmup = run.warmup;
  if (config.secondsPerCombination > 0) {
    RenderSettings probe = settings;
    probe.frames = 1;
    probe.warmup = 0;
    const double seconds = render(probe).medianMs * 1e-3;
    settings.frames = budgetedFrames(config.frames, run.warmup, seconds, config.secondsPerCombination);
    if (settings.frames < config.frames) settings.warmup = 1;
  }
  return render(settings);
}

BenchRun runBench(gpu::Context& context, const BenchConfig& config, const BenchCallbacks& callbacks) {
  const auto start = std::chrono::steady_clock::now();
  const Note note = [&](const std::string& line) {
    if (callbacks.onNote) callbacks.onNote(line);
  };
  BenchRun run;
  run.config = config;
  run.warmup = warmupFrames(config.frames);
  const size_t total = sizeDatasets(context, config, run, note);
  if (config.ranks) // a data set one process cannot hold is skipped by every process
    for (DatasetOutcome& outcome : run.datasets)
      outcome.skipped = config.ranks->any(outcome.skipped);
  runRecorded(context, run, config.copyBytes, config.copyRepeats, start, note, [&] {
    Renderer renderer(context, config.width, config.height);
    const double aspect = double(config.width) / double(config.height);
    size_t done = 0;
    auto record = [&](const Result& r) {
      run.results.push_back(r);
      ++done;
      if (callbacks.onResult) callbacks.onResult(run, run.results.back(), done, total);
    };
    for (DatasetOutcome& outcome : run.datasets) {
      if (outcome.skipped) continue;
      checkTimeLimit(start, config.timeLimitSeconds, done, total); // preparing a data set takes a while
      const Dataset& d = outcome.dataset;
      // Host-side preparation can take minutes at the paper's sizes; a line each keeps a log readable.
      auto since = std::chrono::steady_clock::now();
      const PointCloud cloud =
          config.ranks ? config.ranks->loadShare(d, config.progress) : loadDataset(d, config.progress);
      outcome.points = config.ranks ? config.ranks->sum(cloud.size()) : cloud.size();
      outcome.description = cloud.source;
      note(d.label + ": " + cloud.source + " ready in " + printf1("%.1f s", secondsSince(since)));
      for (Order order : ordersOf(d, config)) {
        checkTimeLimit(start, config.timeLimitSeconds, done, total);
        since = std::chrono::steady_clock::now();
        const OrderScenes scenes = uploadOrder(context, cloud, order, config);
        note(d.label + " / " + orderName(order) + ": ordered and uploaded in " +
             printf1("%.1f s", secondsSince(since)));
        const Camera first = viewCamera(viewsOf(d, config).front(), cloud.bounds, aspect, config.fovY);
        settleWithFirst(
            context, config.methods,
            [&](Method m) { return scenes.find(m.info().layout) && Renderer::supports(context, m); },
            [&](const RenderSettings& s) {
              return renderer.render(*scenes.find(s.method.info().layout), first, s);
            });
        for (View view : viewsOf(d, config)) {
          const Camera camera = viewCamera(view, cloud.bounds, aspect, config.fovY);
          for (Method method : config.methods) {
            if (methodInfo(method).layout == SceneLayout::Octree) continue; // after the orders, on the octree
            checkTimeLimit(start, config.timeLimitSeconds, done, total);
            Result r;
            r.dataset = d.name;
            r.order = order;
            r.view = view;
            r.method = method;
            r.points = cloud.size();
            r.bytesPerPoint = method.info().bytesPerPoint;
            r.camera = describeCamera(camera);
            std::string why;
            const GpuScene* scene = scenes.find(method.info().layout);
            if (!scene) {
              r.status = "unsupported";
              r.reason = scenes.failures.at(method.info().layout);
            } else if (!Renderer::supports(context, method, &why)) {
              r.status = "unsupported";
              r.reason = why;
            } else {
              measureGuarded(
                  r,
                  [&] {
                    r.stats = timeFrames(method, run, [&](const RenderSettings& s) {
                      return renderer.render(*scene, camera, s);
                    });
                  },
                  record);
            }
            if (config.ranks) config.ranks->composite(renderer, camera, r);
            completeRates(r, run.copy);
            record(r);
          }
        }
      }
      checkTimeLimit(start, config.timeLimitSeconds, done, total);
      measureOctreeMethods(context, renderer, config, d, cloud, ordersOf(d, config).front(),
                           viewsOf(d, config), run, record);
    }
  });
  return run;
}

} // namespace pointrast::bench

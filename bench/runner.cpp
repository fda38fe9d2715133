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

// Parallel gather in fixed blocks (as everywhere in src/cloud), so it costs a fraction of the sort.
constexpr uint64_t kGatherBlock = uint64_t(1) << 16;

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
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (seconds > limitSeconds)
    throw TimeLimitReached("time limit of " + printf1("%g", limitSeconds) + " s reached after " +
                           std::to_string(done) + " of " + std::to_string(total) +
                           " combinations; the rest were not run");
}

double settleClocks(const std::function<double(uint32_t frames)>& renderMs) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  uint32_t frames = 1;
  double last = 0;
  for (int round = 0; elapsed() < 3.0; ++round) {
    const double ms = renderMs(frames);
    if (!(ms > 0)) break; // nothing measurable to settle on
    if (round >= 2 && std::abs(ms - last) <= 0.03 * last && elapsed() >= 0.2) break;
    last = ms;
    frames = uint32_t(std::clamp(std::ceil(30.0 / ms), 1.0, 200.0));
  }
  return elapsed();
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
  DisplayColorMode mode = displayColorMode(cloud);
  std::vector<uint32_t> colors(cloud.size());
  displayColors(colors.data(), cloud, 0, cloud.size(), mode);
  cloud.colors = std::move(colors);
  cloud.intensity = {};
  cloud.classification = {};
  cloud.returnNumber = {};
  cloud.pointSourceId = {};
  return cloud;
}

PointCloud reorderedCopy(const PointCloud& src, Order order, uint64_t seed) {
  std::vector<uint64_t> permutation;
  computeOrder(permutation, src, order, seed);
  PointCloud dst;
  dst.scale = src.scale;
  dst.offset = src.offset;
  dst.bounds = src.bounds;
  dst.source = src.source;
  dst.positions.resize(src.positions.size());
  dst.colors.resize(src.colors.size());
  const bool colors = !src.colors.empty();
  parallelBlocks(src.size(), kGatherBlock, [&](uint64_t, uint64_t begin, uint64_t end) {
    for (uint64_t i = begin; i < end; ++i) {
      const uint64_t from = permutation[i];
      dst.positions[3 * i] = src.positions[3 * from];
      dst.positions[3 * i + 1] = src.positions[3 * from + 1];
      dst.positions[3 * i + 2] = src.positions[3 * from + 2];
      if (colors) dst.colors[i] = src.colors[from];
    }
  });
  return dst;
}

void completeRates(Result& r, const gpu::CopyBandwidth& copy) {
  if (!r.ok() || !(r.stats.medianMs > 0)) return;
  const double seconds = r.stats.medianMs * 1e-3;
  r.pointsPerSecond = double(r.stats.points) / seconds;
  r.effectiveBytesPerSecond =
      (r.stats.batch ? double(r.stats.batch->bytesRead) : double(r.stats.points) * r.bytesPerPoint) / seconds;
  r.copyFraction = copy.bytesPerSecond > 0 ? r.effectiveBytesPerSecond / copy.bytesPerSecond : 0;
}

BenchRun runBench(gpu::Context& context, const BenchConfig& config, const BenchCallbacks& callbacks) {
  const auto start = std::chrono::steady_clock::now();
  auto note = [&](const std::string& line) {
    if (callbacks.onNote) callbacks.onNote(line);
  };
  BenchRun run;
  run.device = context.info();
  run.deviceLocalBytes = context.deviceLocalBytes();
  run.config = config;
  run.warmup = warmupFrames(config.frames);

  // Every data set is sized before anything runs, so what will be skipped is said up front.
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

  // Before any scene is resident, so the copy buffers may take their full size.
  run.copy = gpu::measureCopy(context, config.copyBytes, config.copyRepeats);
  note(copyBandwidthText(run.copy));

  Renderer renderer(context, config.width, config.height);
  const double aspect = double(config.width) / double(config.height);
  size_t done = 0;
  try {
    for (DatasetOutcome& outcome : run.datasets) {
      if (outcome.skipped) continue;
      checkTimeLimit(start, config.timeLimitSeconds, done, total); // preparing a data set takes a while
      const Dataset& d = outcome.dataset;
      auto since = std::chrono::steady_clock::now();
      auto secondsSince = [&since] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
      };
      // Host-side preparation can take minutes at the paper's sizes; a line each keeps a log readable.
      PointCloud cloud = loadDataset(d, config.progress);
      outcome.points = cloud.size();
      outcome.description = cloud.source;
      note(d.label + ": " + cloud.source + " ready in " + printf1("%.1f s", secondsSince()));
      for (Order order : ordersOf(d, config)) {
        checkTimeLimit(start, config.timeLimitSeconds, done, total);
        since = std::chrono::steady_clock::now();
        // One scene per layout the methods read (a suite mixing 2021 and batch methods holds both).
        std::map<SceneLayout, std::unique_ptr<GpuScene>> scenes;
        std::map<SceneLayout, std::string> failures;
        {
          PointCloud ordered;
          if (order != Order::Original) ordered = reorderedCopy(cloud, order, config.orderSeed);
          for (SceneLayout layout : layoutsOf(config.methods)) {
            UploadOptions upload;
            upload.layout = layout;
            upload.progress = config.progress;
            try {
              scenes[layout] =
                  std::make_unique<GpuScene>(context, order == Order::Original ? cloud : ordered, upload);
            } catch (const UnsupportedError& e) {
              failures[layout] = e.what(); // out of device memory after all: every combination says so
            }
          }
        } // the reordered host copy is freed here, before the GPU work
        note(d.label + " / " + orderName(order) + ": ordered and uploaded in " +
             printf1("%.1f s", secondsSince()));
        // Clocks up again after the host's work, with the first supported method on the first view.
        for (Method method : config.methods) {
          const SceneLayout layout = methodInfo(method).layout;
          if (layout == SceneLayout::Octree || !scenes[layout] || !Renderer::supports(context, method))
            continue;
          const Camera camera = viewCamera(viewsOf(d, config).front(), cloud.bounds, aspect, config.fovY);
          try {
            settleClocks([&](uint32_t frames) {
              RenderSettings settle;
              settle.method = method;
              settle.frames = frames;
              settle.warmup = 0;
              return renderer.render(*scenes[layout], camera, settle).medianMs;
            });
          } catch (const UnsupportedError&) {
            // Left to the combinations, which report it; a DeviceFault ends the run as there.
          } catch (const InputError&) {
          }
          break;
        }
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
            r.bytesPerPoint = methodInfo(method).bytesPerPoint;
            r.camera = describeCamera(camera);
            std::string why;
            const SceneLayout layout = methodInfo(method).layout;
            if (!scenes[layout]) {
              r.status = "unsupported";
              r.reason = failures[layout];
            } else if (!Renderer::supports(context, method, &why)) {
              r.status = "unsupported";
              r.reason = why;
            } else {
              RenderSettings settings;
              settings.method = method;
              settings.frames = config.frames;
              settings.warmup = run.warmup;
              measureGuarded(
                  r,
                  [&] {
                    if (config.secondsPerCombination > 0) {
                      // One frame timed first decides how many the budget allows.
                      RenderSettings probe = settings;
                      probe.frames = 1;
                      probe.warmup = 0;
                      const double seconds = renderer.render(*scenes[layout], camera, probe).medianMs * 1e-3;
                      settings.frames =
                          budgetedFrames(config.frames, run.warmup, seconds, config.secondsPerCombination);
                      if (settings.frames < config.frames) settings.warmup = 1;
                    }
                    r.stats = renderer.render(*scenes[layout], camera, settings);
                  },
                  [&](const Result& faulted) {
                    run.results.push_back(faulted);
                    ++done;
                    if (callbacks.onResult) callbacks.onResult(run, run.results.back(), done, total);
                  });
            }
            completeRates(r, run.copy);
            run.results.push_back(r);
            ++done;
            if (callbacks.onResult) callbacks.onResult(run, run.results.back(), done, total);
          }
        }
      }
      checkTimeLimit(start, config.timeLimitSeconds, done, total);
      measureOctreeMethods(context, renderer, config, d, cloud, ordersOf(d, config).front(),
                           viewsOf(d, config), run, [&](const Result& r) {
                             run.results.push_back(r);
                             ++done;
                             if (callbacks.onResult) callbacks.onResult(run, run.results.back(), done, total);
                           });
    }
  } catch (const DeviceFault& e) {
    run.stopped = deviceFaultText(e);
    note("stopped: " + run.stopped);
  } catch (const TimeLimitReached& e) {
    run.stopped = e.what();
    note("stopped: " + run.stopped);
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

} // namespace pointrast::bench

#include "bench/lod_suite.h"

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>
#include <thread>

#include "bench/lod_runner.h"
#include "gpu/shared_types.h"
#include "io/format_table.h"
#include "render/lod/lod_scene.h"

namespace pointrast::bench {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Drops the octree's files from the page cache, so that streaming reads them from disk: written pages are
// flushed first (only clean pages can be dropped). Whether every file was dropped.
bool dropFromPageCache(const std::filesystem::path& dir) {
  bool all = true;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file(ec)) continue;
    const int fd = ::open(entry.path().c_str(), O_RDONLY);
    if (fd < 0) {
      all = false;
      continue;
    }
    ::fdatasync(fd);
    all = ::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED) == 0 && all;
    ::close(fd);
  }
  return all && !ec;
}

// Bytes the whole octree takes in the node cache's pages (reads the whole hierarchy).
uint64_t octreeGpuBytes(lod::NodeSource& source) {
  uint64_t pages = 0;
  lod::forEachNode(source, [&](const lod::NodeInfo& node) {
    pages += lod::pagesOf(node.pointCount);
    return true;
  });
  return pages * shared::kLodPageBytes;
}

// Paces frames like a display refreshing at `hz` (0: no pacing).
class Pacer {
public:
  explicit Pacer(double hz) : period_(hz > 0 ? 1.0 / hz : 0), next_(Clock::now()) {}
  void wait() {
    if (period_ <= 0) return;
    next_ += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_));
    const auto now = Clock::now();
    if (next_ > now)
      std::this_thread::sleep_until(next_);
    else
      next_ = now; // a slow frame: the display waits for the next refresh from now
  }

private:
  double period_;
  Clock::time_point next_;
};

RenderSettings lodSettings(uint32_t frames, uint32_t warmup) {
  RenderSettings s;
  s.method = pointMethod("lod");
  s.frames = frames;
  s.warmup = warmup;
  return s;
}

Bounds boundsOf(const lod::OctreeMetadata& meta) {
  return meta.bounds.empty() ? meta.cube : meta.bounds;
}

void runSweeps(gpu::Context& context, Renderer& renderer, const LodSuiteConfig& config,
               const Dataset& dataset, lod::NodeSource& source, LodSuiteRun& run,
               const LodSuiteCallbacks& callbacks) {
  lod::LodScene scene(context, source);
  const Bounds bounds = boundsOf(source.metadata());
  const double aspect = double(config.width) / double(config.height);
  settleClocks([&](uint32_t frames) {
    return renderer
        .render(scene, viewCamera(View::Overview, bounds, aspect, config.fovY), lodSettings(frames, 0))
        .medianMs;
  });
  auto measure = [&](View view, double minNodePx, uint64_t budget) {
    LodSweepResult r;
    r.dataset = dataset.name;
    r.view = view;
    r.minNodePx = minNodePx;
    r.pointBudget = budget;
    const Camera camera = viewCamera(view, bounds, aspect, config.fovY);
    r.camera = describeCamera(camera);
    RenderSettings settings = lodSettings(config.frames, run.warmup);
    settings.minNodePx = minNodePx;
    settings.pointBudget = budget;
    measureGuarded(
        r, [&] { r.stats = renderer.render(scene, camera, settings); },
        [&](const LodSweepResult& faulted) { run.sweeps.push_back(faulted); });
    run.sweeps.push_back(r);
    if (callbacks.onSweep) callbacks.onSweep(run, run.sweeps.back());
  };
  for (View view : config.views) {
    for (uint64_t budget : config.pointBudgets)
      measure(view, 100, budget);
    for (double minNodePx : config.minNodePx)
      measure(view, minNodePx, 0);
  }
}

LodFrameSample streamFrame(Renderer& renderer, lod::LodScene& scene, const Camera& camera,
                           uint64_t bytesBefore) {
  const auto start = Clock::now();
  const FrameStats stats = renderer.renderFrame(scene, camera, lodSettings(1, 0));
  LodFrameSample s;
  s.wallMs = msSince(start);
  s.gpuMs = stats.medianMs;
  s.pointsDrawn = stats.lod->pointsDrawn;
  s.bytesStreamed = stats.lod->bytesStreamed - bytesBefore;
  s.converged = stats.lod->converged;
  return s;
}

void runStreaming(gpu::Context& context, Renderer& renderer, const LodSuiteConfig& config,
                  const Dataset& dataset, const DatasetOctree& octree, lod::NodeSource& source,
                  LodSuiteRun& run, const LodSuiteCallbacks& callbacks) {
  LodStreamResult r;
  r.dataset = dataset.name;
  r.octreePoints = source.metadata().pointCount;
  measureGuarded(
      r,
      [&] {
        r.octreeGpuBytes = octreeGpuBytes(source);
        lod::LodOptions options;
        options.gpuBytes = std::max<uint64_t>(r.octreeGpuBytes / std::max(1u, config.cacheDivisor),
                                              16 * uint64_t(shared::kLodPageBytes));
        lod::LodScene scene(context, source, options);
        r.cacheBytes = scene.stats().cacheBytes;
        r.pageCacheDropped = dropFromPageCache(octree.path);
        const Bounds bounds = boundsOf(source.metadata());
        const std::vector<Camera> flight = flightCameras(bounds, config.flightFrames, config.fovY);
        if (!flight.empty())
          r.flightCameras = {describeCamera(flight.front()), describeCamera(flight.back())};
        Pacer pacer(config.displayHz);
        for (const Camera& camera : flight) {
          r.flight.push_back(streamFrame(renderer, scene, camera, 0));
          pacer.wait();
        }
        for (const Camera& camera : jumpCameras(bounds, config.jumps, config.fovY)) {
          LodJumpResult jump;
          jump.camera = describeCamera(camera);
          const uint64_t before = scene.stats().bytesStreamed;
          const auto start = Clock::now();
          while (jump.frames < config.jumpFrameLimit && !jump.converged) {
            const LodFrameSample s = streamFrame(renderer, scene, camera, before);
            ++jump.frames;
            jump.converged = s.converged;
            jump.bytesStreamed = s.bytesStreamed;
            jump.maxGpuMs = std::max(jump.maxGpuMs, s.gpuMs);
            jump.maxWallMs = std::max(jump.maxWallMs, s.wallMs);
            pacer.wait();
          }
          jump.seconds = msSince(start) * 1e-3;
          r.jumps.push_back(jump);
        }
        r.last = scene.stats();
      },
      [&](const LodStreamResult& faulted) { run.streams.push_back(faulted); });
  run.streams.push_back(r);
  if (callbacks.onStream) callbacks.onStream(run, run.streams.back());
}

} // namespace

std::vector<Camera> flightCameras(const Bounds& bounds, uint32_t frames, double fovY) {
  std::vector<Camera> cameras;
  const glm::dvec3 size = bounds.size();
  const double height = 0.05 * std::max({size.x, size.y, 1e-3});
  const glm::dvec2 from = glm::dvec2(bounds.min) + 0.1 * glm::dvec2(size),
                   to = glm::dvec2(bounds.max) - 0.1 * glm::dvec2(size);
  const glm::dvec2 heading = glm::normalize(to - from + glm::dvec2(1e-12, 0));
  for (uint32_t k = 0; k < frames; ++k) {
    const double t = frames > 1 ? double(k) / double(frames - 1) : 0.0;
    Camera c;
    c.fovY = fovY;
    c.eye = glm::dvec3(from + t * (to - from), bounds.max.z + height);
    c.target = c.eye + glm::dvec3(4 * height * heading, -height); // atan(1/4): 14 degrees down
    cameras.push_back(c);
  }
  return cameras;
}

std::vector<Camera> jumpCameras(const Bounds& bounds, uint32_t count, double fovY) {
  std::vector<Camera> cameras;
  const glm::dvec3 size = bounds.size();
  const double height = 0.05 * std::max({size.x, size.y, 1e-3});
  for (uint32_t k = 0; k < count; ++k) {
    // The additive recurrence of the plastic number (a 2D low-discrepancy sequence): far-apart views
    // whatever the count.
    const double a = std::fmod(0.5 + (k + 1) * 0.7548776662466927, 1.0);
    const double b = std::fmod(0.5 + (k + 1) * 0.5698402909980532, 1.0);
    const double angle = 2.39996322972865332 * k; // the golden angle: a new direction each jump
    Camera c;
    c.fovY = fovY;
    c.eye = glm::dvec3(bounds.min.x + (0.1 + 0.8 * a) * size.x, bounds.min.y + (0.1 + 0.8 * b) * size.y,
                       bounds.max.z + height);
    const glm::dvec2 direction(std::cos(angle), std::sin(angle));
    c.target = c.eye + glm::dvec3(2.14 * height * direction, -height); // atan(1/2.14): 25 degrees down
    cameras.push_back(c);
  }
  return cameras;
}

LodSuiteRun runLodSuite(gpu::Context& context, const LodSuiteConfig& config,
                        const LodSuiteCallbacks& callbacks) {
  const auto start = Clock::now();
  const Note note = [&](const std::string& line) {
    if (callbacks.onNote) callbacks.onNote(line);
  };
  LodSuiteRun run;
  run.config = config;
  run.warmup = warmupFrames(config.frames);
  runRecorded(context, run, config.copyBytes, config.copyRepeats, start, note, [&] {
    Renderer renderer(context, config.width, config.height);
    const size_t total = config.datasets.size();
    size_t done = 0;
    for (const Dataset& d : config.datasets) {
      checkTimeLimit(start, config.timeLimitSeconds, done, total);
      DatasetOutcome outcome;
      auto [source, octree] = openDatasetOctree(d, config.octrees, config.progress, outcome, note);
      ++done;
      if (outcome.skipped) {
        run.datasets.push_back(outcome);
        continue;
      }
      run.datasets.push_back(outcome);
      run.octrees.emplace_back(d.name, octree);
      measureDataset(d, note, [&] {
        runSweeps(context, renderer, config, d, *source, run, callbacks);
        checkTimeLimit(start, config.timeLimitSeconds, done, total);
        runStreaming(context, renderer, config, d, octree, *source, run, callbacks);
      });
    }
  });
  return run;
}

} // namespace pointrast::bench

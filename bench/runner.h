// The benchmark runner: for each data set, each vertex order, each view and each method, GPU time of
// whole frames (clear + render + resolve) from timestamp queries after a warm-up, with the device's
// buffer-copy bandwidth measured in the same run (docs/design.md, "Measuring performance").
//
// Memory: the host holds the data set in its original order (16 B/point: positions and display colors;
// a file's other attributes are dropped once its colors are decided) plus one reordered copy and its
// permutation (8 B/point) while that order is uploaded; the GPU holds one order of one data set at a time,
// in each scene layout a method of the run reads (float for the 2019/2021 methods, batched for the 2022
// batch methods: 16 B/point each).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "base/text.h" // bytesText
#include "bench/octree_cache.h"
#include "bench/views.h"
#include "cloud/order.h"
#include "gpu/bandwidth.h"
#include "gpu/context.h"
#include "render/clock_settle.h"
#include "render/renderer.h"

namespace pointrast::bench {

struct Dataset {
  std::string name;    // short id for JSON and file names: "retz-like", "terrain-20k", "autzen"
  std::string label;   // row label of the tables: "retz-like (terrain, 145 M)"
  std::string source;  // a file path or a scene name (terrain, tls)
  uint64_t points = 0; // points to generate (scenes); ignored for files
  uint64_t seed = 1;   // scene seed
  bool file = false;   // source is a file
  // The orders and views measured for this data set; empty: those of the BenchConfig (a suite measures
  // some of its data sets in more orders or views than others).
  std::vector<Order> orders;
  std::vector<View> views;
};

struct Result;

// A run on several processes (`mpirun -np N pointrast bench`, docs/mpi.md), as the command line wires it:
// each process loads its share of a data set and times its frames of it; after every combination each
// process composites its last frame (a collective: every process measures the same combinations).
struct BenchRanks {
  // This process's share of a data set, ready to upload (loadDataset's whole cloud on one process).
  std::function<PointCloud(const Dataset& dataset, bool progress)> loadShare;
  // After a combination's frames on this process (its status says whether it drew): the last frame of
  // `renderer` composited on rank 0, and the result made the job's there (every process's points, the
  // slowest process's time, the figures of each in Result::ranks).
  std::function<void(Renderer& renderer, const Camera& camera, Result& result)> composite;
  // Whether any process says true (a data set another process cannot hold is skipped by all).
  std::function<bool(bool)> any;
  // The sum over every process.
  std::function<uint64_t(uint64_t)> sum;
};

struct BenchConfig {
  std::vector<Dataset> datasets;
  std::vector<Method> methods;
  std::vector<Order> orders;
  std::vector<View> views;
  uint32_t width = 1920, height = 1080;
  uint32_t frames = 50; // timed frames per combination; warm-up is warmupFrames(frames)
  // GPU seconds one combination may take (0 = no limit): a method whose frame, timed once first, would
  // make warm-up + frames exceed it is timed over fewer frames (budgetedFrames) after one warm-up frame,
  // so the paper-sized suites fit a session while the fast methods keep every frame.
  double secondsPerCombination = 0;
  // Wall seconds after which no further combination starts (0 = no limit): the run ends as after a device
  // fault, with what it measured, so a lease or a CI job that must end by a time still gets its reports.
  double timeLimitSeconds = 0;
  double fovY = 60.0;
  uint64_t orderSeed = 1; // for the shuffled orders
  uint64_t copyBytes = uint64_t(1) << 30;
  int copyRepeats = 10;
  std::optional<BenchRanks> ranks; // a run on several processes; no octree methods, no time limit
  bool progress = true; // generation, reading and upload progress (drawn only on a terminal)
  // The octrees the LOD methods draw (bench/lod_runner.h); without one, their results say so.
  OctreeProvider octrees;
};

// One number through a printf format: printf1("%.1f s", 2.34) = "2.3 s" (at most 63 characters).
std::string printf1(const char* format, double value);
// The line both runners log once the copy bandwidth is measured: "copy bandwidth: 4305.4 GB/s (read +
// write, 953.7 MiB copied, median of 10)".
std::string copyBandwidthText(const gpu::CopyBandwidth& copy);

// Clocks are settled before the first combination of each scene (render/clock_settle.h).
using pointrast::kSettleMaxRounds;
using pointrast::kSettleMaxSeconds;
using pointrast::kSettleMinSeconds;
using pointrast::kSettleRoundMs;
using pointrast::kSettleTolerance;
using pointrast::settleClocks;
using pointrast::settlesClocks;

// Untimed frames before the timed ones: a tenth of them, at least two (pipeline creation, clocks).
uint32_t warmupFrames(uint32_t frames);
// Frames to time for a method whose probe frame took probeSeconds: `frames` if warm-up + frames fit in
// `budget` seconds (or budget is 0), else as many as fit, at least minFrames (and at most frames).
constexpr uint32_t kMinBudgetedFrames = 3;
uint32_t budgetedFrames(uint32_t frames, uint32_t warmup, double probeSeconds, double budget,
                        uint32_t minFrames = kMinBudgetedFrames);

// Bytes per pixel of the render targets of every method a Renderer may hold at once: framebuffer (8),
// image (4), canonical words (8), HQS accumulators (16), HQS1R's (24) and batch-hqs's (24), rounded up.
constexpr uint64_t kTargetBytesPerPixel = 88;
// Host bytes per point: the original (16 B) + a reordered copy (16 B) + its permutation (8 B).
constexpr uint64_t kHostBytesPerPoint = 40;

// Physical memory of this machine in bytes (0 if unknown).
uint64_t physicalMemory();

struct MemoryEstimate {
  uint64_t gpuBytes = 0, hostBytes = 0; // needed
  uint64_t gpuHave = 0, hostHave = 0;   // device-local heaps; physical memory of this machine
  bool fits() const { return gpuBytes <= gpuHave && hostBytes <= hostHave; }
  std::string describe() const; // "needs 12.7 GB of GPU memory (has 80.0 GB) and ..."
};
// GPU: points x 16 B in every layout the methods read (float when `methods` is empty) + targets; host:
// points x 40 B, plus the GPU bytes on a software device (its "device memory" is host memory).
MemoryEstimate estimateMemory(const gpu::Context& context, uint64_t points, uint32_t width, uint32_t height,
                              const std::vector<Method>& methods = {});
// The scene layouts `methods` read, each once, float first.
std::vector<SceneLayout> layoutsOf(const std::vector<Method>& methods);

struct Result {
  std::string dataset; // Dataset::name
  Order order = Order::Original;
  View view = View::Overview;
  Method method;
  std::string status = "ok"; // "ok", or "unsupported" (reason says why: device feature, memory)
  std::string reason;
  uint64_t points = 0;
  FrameStats stats;
  uint32_t bytesPerPoint = 0;
  double pointsPerSecond = 0;
  double effectiveBytesPerSecond = 0; // points x bytesPerPoint / median time; batch methods: the bytes
                                      // the frame read (FrameStats::batch) / median time
  double copyFraction = 0;            // effectiveBytesPerSecond / copy bandwidth (read + write)
  std::string camera;                 // describeCamera(), to reproduce the view with `pointrast render`
  // A run on several processes (BenchRanks): render --json's "mpi" object (each process's time and points,
  // the composite's); null on one process.
  nlohmann::json ranks;
  bool ok() const { return status == "ok"; }
};

struct DatasetOutcome {
  Dataset dataset;
  uint64_t points = 0;     // points of the cloud (from the file header before it is read)
  std::string description; // the cloud's source text ("terrain, 4000000 points, seed 1")
  MemoryEstimate memory;
  bool skipped = false;
  std::string reason; // why it was skipped
};

// What every benchmark run records besides its results: where it ran, the copy bandwidth measured in it,
// its data sets, and how it ended.
struct RunRecord {
  gpu::DeviceInfo device;
  uint64_t deviceLocalBytes = 0;
  gpu::CopyBandwidth copy;
  uint32_t warmup = 0; // untimed frames before the timed ones (per camera for the sphere runner)
  std::vector<DatasetOutcome> datasets;
  double seconds = 0; // wall time of the whole run (not a GPU figure)
  // Why the run ended before its last combination: the GPU stopped making progress (every later submission
  // would wait on the stuck one) or the time limit passed. The reports hold what was measured before.
  std::string stopped;
  bool faulted = false; // stopped by a device fault (the CLI then exits 1 after writing the reports)
};

struct BenchRun : RunRecord {
  BenchConfig config;
  std::vector<Result> results;
  std::vector<std::pair<std::string, DatasetOctree>> octrees; // by Dataset::name: the LOD methods' octrees
};

struct BenchCallbacks {
  // After each combination, with the run so far (device, copy bandwidth, settings); done counts from 1
  // to total.
  std::function<void(const BenchRun& run, const Result& result, size_t done, size_t total)> onResult;
  // Memory statements, skipped data sets, the copy bandwidth: one line each.
  std::function<void(const std::string&)> onNote;
};

// Runs `measure` for one combination of a run (Result, SphereResult): an UnsupportedError (a device feature,
// out of device memory) or an InputError (a data set beyond what a method addresses) becomes status
// "unsupported" with the message. A DeviceFault sets status "device-fault", hands the result to `record`
// and is rethrown: the run ends there, since every later submission would wait on the stuck one.
template <class R, class Measure, class Record>
void measureGuarded(R& result, Measure&& measure, Record&& record) {
  try {
    measure();
    gpu::noteMeasuredResult();
  } catch (const UnsupportedError& e) {
    result.status = "unsupported";
    result.reason = e.what();
  } catch (const InputError& e) {
    result.status = "unsupported";
    result.reason = e.what();
  } catch (const DeviceFault& e) {
    result.status = "device-fault";
    result.reason = e.what();
    record(result);
    throw;
  }
}

// One line of a run's log (memory statements, skipped data sets, the copy bandwidth, times).
using Note = std::function<void(const std::string&)>;

// Wall seconds since `since` (for logs and the time limit; never a GPU figure).
double secondsSince(std::chrono::steady_clock::time_point since);

// Points per second, effective bandwidth and its fraction of the copy bandwidth of a measured result.
void completeRates(Result& result, const gpu::CopyBandwidth& copy);

// The line a run that met a device fault ends with (RunRecord::stopped).
std::string deviceFaultText(const DeviceFault& fault);

// The frame both runners share. Fills the record's device, measures the copy bandwidth before anything is
// resident (so the copy buffers may take their full size), then runs `combinations()`; a device fault or
// the time limit (TimeLimitReached) ends it with what was measured, said in `stopped`. Keeps the wall time
// since `start`.
template <class Combinations>
void runRecorded(gpu::Context& context, RunRecord& run, uint64_t copyBytes, int copyRepeats,
                 std::chrono::steady_clock::time_point start, const Note& note, Combinations&& combinations);

// Renders the combination's scene from its camera with `settings` (method, frames, warm-up) and returns
// the frames' statistics: how the timing helpers below reach a Renderer and whatever scene it draws.
using RenderFrames = std::function<FrameStats(const RenderSettings& settings)>;

// Before a scene's first combination (GPUs only, settlesClocks): renders with the first of `methods` that
// `runs` accepts until the GPU's clocks are up again after the host's work (settleClocks). What goes wrong
// here is left to the combinations, which report it; a DeviceFault ends the run as there.
void settleWithFirst(const gpu::Context& context, std::span<const Method> methods,
                     const std::function<bool(Method)>& runs, const RenderFrames& render);

// Times one combination of `method`: the run's frames after its warm-up, or as many as the time budget
// allows after a probe frame (budgetedFrames).
FrameStats timeFrames(Method method, const BenchRun& run, const RenderFrames& render);

// Thrown by checkTimeLimit between combinations: the run ends there like after a device fault.
struct TimeLimitReached : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// Throws TimeLimitReached when limitSeconds > 0 and more than that has passed since start; `done` and
// `total` combinations go into the message.
void checkTimeLimit(std::chrono::steady_clock::time_point start, double limitSeconds, size_t done,
                    size_t total);

// Runs the whole matrix. Data sets that do not fit are skipped and say why (DatasetOutcome). Throws
// InputError for an unreadable file, UnsupportedError if the copy buffers cannot be had.
BenchRun runBench(gpu::Context& context, const BenchConfig& config, const BenchCallbacks& callbacks = {});

// The cloud of a data set, ready to upload: positions and display colors only.
PointCloud loadDataset(const Dataset& dataset, bool progress);
// What a loaded data set keeps for the benchmarks: its colors replaced by the display colors of `mode`,
// and the attributes rendering never reads dropped.
void keepDisplayColorsOnly(PointCloud& cloud, const DisplayColorMode& mode);

template <class Combinations>
void runRecorded(gpu::Context& context, RunRecord& run, uint64_t copyBytes, int copyRepeats,
                 std::chrono::steady_clock::time_point start, const Note& note, Combinations&& combinations) {
  run.device = context.info();
  run.deviceLocalBytes = context.deviceLocalBytes();
  run.copy = gpu::measureCopy(context, copyBytes, copyRepeats);
  note(copyBandwidthText(run.copy));
  try {
    combinations();
  } catch (const DeviceFault& e) {
    run.stopped = deviceFaultText(e);
    run.faulted = true;
    note("stopped: " + run.stopped);
  } catch (const TimeLimitReached& e) {
    run.stopped = e.what();
    note("stopped: " + run.stopped);
  }
  run.seconds = secondsSince(start);
}

} // namespace pointrast::bench

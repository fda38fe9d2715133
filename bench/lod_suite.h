// The `lod` suite: the LOD method on octrees of stand-ins (built once, bench/octree_cache.h).
//   sweeps     the full-detail frame time of `lod` against the point budget (--min-node-px at its default
//              of 100) and against --min-node-px (no budget), from the overview and the closeup; each point
//              streamed in before it is timed as `render` times a frame
//   streaming  the node cache limited to 1/8 of the octree's GPU bytes: a camera flight low across the
//              cloud, then jumps between far-apart views, every frame one Renderer::renderFrame paced like
//              a 60 Hz display: per-frame GPU time (timestamps) and wall time (what a viewer's frame takes,
//              host work included), frames until each jump converges, and the rate nodes stream from disk
//              (the octree's files are dropped from the page cache first where the system allows)
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "bench/runner.h"

namespace pointrast::bench {

struct LodSuiteConfig {
  std::vector<Dataset> datasets;
  uint32_t width = 2560, height = 1140;
  uint32_t frames = 20; // timed frames of each sweep point; warm-up is warmupFrames(frames)
  double fovY = 60;
  std::vector<View> views{View::Overview, View::Closeup};
  std::vector<uint64_t> pointBudgets{1'000'000, 3'000'000, 10'000'000, 30'000'000, 100'000'000, 300'000'000};
  std::vector<double> minNodePx{1000, 300, 100, 30, 10};
  uint32_t cacheDivisor = 8;     // streaming: GPU memory for the node cache = the octree's GPU bytes / this
  uint32_t flightFrames = 600;   // frames of the flight from one corner of the cloud to the other
  uint32_t jumps = 8;            // views jumped to after the flight
  uint32_t jumpFrameLimit = 600; // frames a jump may take to converge before it counts as not converged
  double displayHz = 60;         // streaming frames are paced at this rate (0: as fast as they go)
  uint64_t copyBytes = uint64_t(1) << 30; // the copy bandwidth measured with the run (runner.h)
  int copyRepeats = 10;
  double timeLimitSeconds = 0;   // as BenchConfig::timeLimitSeconds
  bool progress = true;
  OctreeProvider octrees;
};

struct LodSweepResult {
  std::string dataset;
  View view = View::Overview;
  double minNodePx = 100;
  uint64_t pointBudget = 0; // 0: none
  std::string status = "ok";
  std::string reason;
  FrameStats stats;
  std::string camera;
  bool ok() const { return status == "ok"; }
};

struct LodFrameSample {
  double gpuMs = 0;  // timestamps around the frame's uploads and drawing
  double wallMs = 0; // Renderer::renderFrame from call to return: selection, uploads, drawing, waiting
  uint64_t pointsDrawn = 0;
  uint64_t bytesStreamed = 0; // since the streaming run began
  bool converged = false;
};

struct LodJumpResult {
  std::string camera;
  uint32_t frames = 0; // frames drawn until converged, that frame included
  bool converged = false;
  double seconds = 0;         // wall time until converged (or the limit)
  uint64_t bytesStreamed = 0; // during the jump
  double maxGpuMs = 0, maxWallMs = 0;
};

struct LodStreamResult {
  std::string dataset;
  std::string status = "ok";
  std::string reason;
  uint64_t octreePoints = 0;
  uint64_t octreeGpuBytes = 0; // every node in the node cache's pages
  uint64_t cacheBytes = 0;
  bool pageCacheDropped = false; // the octree's files were dropped from the page cache before streaming
  std::vector<std::string> flightCameras; // first and last
  std::vector<LodFrameSample> flight;
  std::vector<LodJumpResult> jumps;
  lod::LodStats last; // the scene's totals after the last frame
  bool ok() const { return status == "ok"; }
};

struct LodSuiteRun {
  gpu::DeviceInfo device;
  uint64_t deviceLocalBytes = 0;
  gpu::CopyBandwidth copy;
  LodSuiteConfig config;
  uint32_t warmup = 0;
  std::vector<DatasetOutcome> datasets;
  std::vector<std::pair<std::string, DatasetOctree>> octrees;
  std::vector<LodSweepResult> sweeps;
  std::vector<LodStreamResult> streams;
  double seconds = 0;
  std::string stopped; // as BenchRun::stopped
};

struct LodSuiteCallbacks {
  std::function<void(const std::string&)> onNote; // one line each: octrees, streaming progress
  std::function<void(const LodSuiteRun&, const LodSweepResult&)> onSweep;
  std::function<void(const LodSuiteRun&, const LodStreamResult&)> onStream;
};

// The cameras of the flight: `frames` views evenly along the diagonal of the bounds, from 10 % to 90 % of it,
// at 5 % of the larger horizontal extent above the top, looking ahead and 14 degrees down.
std::vector<Camera> flightCameras(const Bounds& bounds, uint32_t frames, double fovY);
// The jumps' cameras: `count` views spread over the bounds (a fixed low-discrepancy sequence), each at the
// flight's height, looking in a different direction 25 degrees down.
std::vector<Camera> jumpCameras(const Bounds& bounds, uint32_t count, double fovY);

LodSuiteRun runLodSuite(gpu::Context& context, const LodSuiteConfig& config,
                        const LodSuiteCallbacks& callbacks = {});

} // namespace pointrast::bench

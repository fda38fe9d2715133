// The sphere benchmark runner (suite spheres2023): for each particle data set, each GPU layout the set can
// be held in, each orbit, each sphere method of the method table (so methods added to it are measured
// too), each billboard and conservative rasterization off/on (methods that rasterize billboards; the others
// once): the GPU time of whole frames from timestamp queries, per camera a warm-up and then `frames` timed
// frames, and per combination the median over the orbit's cameras of each camera's median. The device's
// buffer-copy bandwidth is measured in the same run, as by the point runner (runner.h).
//
// Memory: the host holds the generated set (16 B/particle: position and color, one global radius); the GPU
// holds it in one layout at a time (up to 32 B/particle) plus each method's targets.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bench/runner.h"
#include "bench/views.h"
#include "render/spheres/sphere_renderer.h"

namespace pointrast::bench {

struct SphereBenchConfig {
  std::vector<Dataset> datasets;       // Dataset::source: a particle scene name; points: its particles
  std::vector<SphereMethod> methods;   // empty: every row of sphereMethodTable()
  std::vector<ParticleLayout> layouts; // each used where the set allows it (xyz: one global color)
  std::vector<SphereBillboard> billboards;
  std::vector<bool> conservative; // off and/or on, for the methods that rasterize billboards
  std::vector<Orbit> orbits;
  uint32_t cameras = 10; // per orbit
  uint32_t width = 1920, height = 1080;
  uint32_t frames = 5; // timed frames per camera; warm-up is warmupFrames(frames)
  // GPU seconds one combination may take over all cameras (0 = no limit): a pipeline whose first frame
  // shows it would take longer is timed over fewer frames per camera (at least one, no warm-up).
  double secondsPerCombination = 0;
  double timeLimitSeconds = 0; // as BenchConfig::timeLimitSeconds
  double fovY = 60.0;
  uint64_t copyBytes = uint64_t(1) << 30;
  int copyRepeats = 10;
  bool progress = true;
};

// Render-target bytes per pixel: the shared image (4) and sphere-compute's visibility buffer (8), plus
// per other method its attachments (color, index, depth: 12, counted as 16 for what mesh and ray-tracing
// pipelines may add); and fixed buffers: sphere-compute's chunk list (64 MiB), upload staging (64 MiB),
// frame constants and readback.
constexpr uint64_t kSphereSharedBytesPerPixel = 12;
constexpr uint64_t kSphereMethodBytesPerPixel = 16;
constexpr uint64_t kSphereFixedBytes = uint64_t(160) << 20;
// Host bytes per generated particle: position (12) and color (4), and while uploading the spatial order
// (cloud/order.h: 8 B sorted indices and the 4 B order kept, at most 12; counted as 16).
constexpr uint64_t kSphereHostBytesPerParticle = 32;

// GPU: particles x the largest bytes per particle of `layouts` + targets of `methods` methods; host:
// particles x 16 B, plus the GPU bytes on a software device.
MemoryEstimate estimateSphereMemory(const gpu::Context& context, uint64_t particles, uint32_t width,
                                    uint32_t height, const std::vector<ParticleLayout>& layouts,
                                    size_t methods);

struct SphereResult {
  std::string dataset; // Dataset::name
  ParticleLayout layout = ParticleLayout::Vec4x2;
  Orbit orbit = Orbit::Short;
  SphereMethod method = SphereMethod::Compute;
  SphereBillboard billboard = SphereBillboard::Screen; // meaningful where billboards() is true
  bool conservative = false;
  std::string status = "ok"; // "ok", "unsupported" (reason says why), "device-fault"
  std::string reason;
  uint64_t particles = 0;
  uint32_t frames = 0;           // timed frames per camera
  std::vector<double> cameraMs;  // median GPU ms of each camera measured
  double medianMs = 0;           // median of cameraMs: the figure of the tables
  double minMs = 0, maxMs = 0;   // of cameraMs
  uint64_t clampedSpheres = 0;   // sphere-points: the most spheres clamped to the largest point, any camera
  uint64_t largeChunks = 0;      // sphere-compute: the most large-sphere chunks of a camera's frame
  uint64_t spilledSpheres = 0;   // sphere-compute: the most spilled large spheres of a camera's frame
  uint64_t batches = 0;          // sphere-compute: batches of 128 particles (occlusion culling)
  uint64_t visibleBatches = 0;   // sphere-compute: the most batches a camera's last frame found visible
  uint32_t bytesPerParticle = 0; // of the layout
  double particlesPerSecond = 0;
  double effectiveBytesPerSecond = 0; // particles x bytesPerParticle / median time
  double copyFraction = 0;            // effectiveBytesPerSecond / copy bandwidth
  bool ok() const { return status == "ok"; }
  bool billboards() const { return sphereMethodTakesBillboards(method); }
};

// The cameras of one orbit of one data set, as describeCamera() gives them (to reproduce a view).
struct SphereOrbitCameras {
  std::string dataset;
  Orbit orbit = Orbit::Short;
  std::vector<std::string> cameras;
};

struct SphereBenchRun : RunRecord {
  SphereBenchConfig config; // methods filled in when the configuration left them empty
  std::vector<SphereOrbitCameras> cameras;
  std::vector<SphereResult> results;
  // Layouts a data set cannot be held in exactly (xyz drops per-particle colors), one line each.
  std::vector<std::string> skippedLayouts;
};

struct SphereBenchCallbacks {
  // After each combination; done counts from 1 to total.
  std::function<void(const SphereBenchRun& run, const SphereResult& result, size_t done, size_t total)>
      onResult;
  // Memory statements, skipped data sets and layouts, the copy bandwidth: one line each.
  std::function<void(const std::string&)> onNote;
};

// The combinations of one data set and layout per orbit, in the order they run: every method, and for
// those that rasterize billboards every billboard x conservative setting. Each has its method, billboard
// and conservative set.
std::vector<SphereResult> sphereCombinations(const SphereBenchConfig& config);

// Runs the whole matrix. Data sets that do not fit are skipped and say why; a device fault ends the run with
// what was measured before (SphereBenchRun::stopped). Throws UnsupportedError if the copy buffers cannot
// be had, InputError for an unknown particle scene.
SphereBenchRun runSphereBench(gpu::Context& context, const SphereBenchConfig& config,
                              const SphereBenchCallbacks& callbacks = {});

} // namespace pointrast::bench

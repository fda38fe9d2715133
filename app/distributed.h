// `mpirun -np N pointrast render ...` (docs/mpi.md): what a rank of a distributed render does besides what
// every render does. Each rank draws its share of the points on its own device; the closest-point words of
// every rank are composited on rank 0 by a MIN, and rank 0 alone resolves, writes and reports the frame.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cloud/cloud.h"
#include "gpu/context.h"
#include "input.h"
#include "render/composite.h"
#include "render/renderer.h"

namespace pointrast::app {

// Whether this process is a rank of a job mpirun started (of any size).
bool distributedRun();

// The blending methods, whose frames composite in HQS steps (compositeHqsFrame): hqs, hqs1r, batch-hqs,
// lod-hqs.
bool compositesInSteps(const MethodInfo& info);

// The device of this rank: --device or POINTRAST_DEVICE when given, else local rank mod the number of
// devices of the best type on the host (discrete GPUs, else integrated, ...). The device line is not
// printed by each rank: announceRanks() prints them all on rank 0.
void chooseRankDevice(gpu::ContextOptions& options);
// Rank 0 prints one line per rank (host, device) on stderr unless quiet and returns them ("host: device",
// rank 0 first); the other ranks get nothing. A collective.
std::vector<std::string> announceRanks(const gpu::Context& context, bool quiet);

// Refuses, before anything is read, what a distributed render does not do (a camera path, the sphere
// methods, methods that keep no depth per pixel to composite). Throws InputError.
void checkDistributed(const RenderSettings& settings, bool cameraPath, bool spheres);

// This rank's share of the input: a generated scene generates only its points, a file is read and only
// its range kept (readers read the whole file for now); ranges are whole batches of 10,240 points, so the
// batch methods cut the same batches as one process would. The bounds are the whole input's (a
// collective), so every rank places its points relative to the same origin and the camera is the same.
PointCloud loadShare(const InputSpec& spec);

// The display colors every rank uses: rank 0's choice (percentile ramps come from its share).
DisplayColorMode agreeColors(const DisplayColorMode& mine);

// The rank's settings for its frames: the resolve stage left for the composite, words captured.
RenderSettings rankSettings(const RenderSettings& settings);

struct CompositeStats {
  uint32_t ranks = 1;
  double renderMs = 0;              // the slowest rank's median GPU time of a frame
  std::vector<double> rankMs;       // each rank's median, rank 0 first
  uint64_t points = 0;              // points drawn by all ranks
  std::vector<uint64_t> rankPoints; // points drawn by each rank, rank 0 first
  double readbackMs = 0;            // rank 0: its words read back from the device
  double compositeMs = 0;           // rank 0: the MIN over all ranks' words (wall clock)
  std::string compositePath;        // how: in shared memory (one host) or by MPI_Reduce
  double resolveMs = 0;             // rank 0: the composited words to the image (wall clock)
  double resolveFirstMs = 0;        // rank 0, render only: the first resolve, its pipelines made in it
  uint64_t bytesMoved = 0;          // sent to the composite: 8 B a pixel from every rank but 0 (HQS: 32)
  std::optional<PostStats> post;    // the resolve stage on rank 0
  std::vector<std::string> devices; // "host: device" per rank
};

// The words of every rank (one a pixel, as Renderer::framebufferWords() returns them for `settings`
// rendered without the resolve stage) composited on rank 0 by their MIN and resolved there with `settings`
// (render/composite.h). Returns the image on rank 0, nothing elsewhere; *ended receives the words the
// composited frame ended with (CompositeResolver::resolve). Fills out's compositeMs, bytesMoved, post and
// resolveMs; with `composited`, the words were composited already (minToRoot) and only resolved here. A
// collective; the render and serve commands' one composite.
std::vector<uint32_t> compositeWords(CompositeResolver& resolver, std::span<uint64_t> words,
                                     const Camera& camera, const RenderSettings& settings, double int40Scale,
                                     CompositeStats& out, std::vector<uint64_t>* ended = nullptr,
                                     bool composited = false);

// After this rank's timed frames (stats): composites the last frame on rank 0 and resolves it there.
// Returns the image on rank 0, nothing elsewhere. `int40Scale` is the int40 steps per unit the frames used.
// A collective.
std::vector<uint32_t> compositeFrame(gpu::Context& context, Renderer& renderer, const Camera& camera,
                                     const RenderSettings& settings, double int40Scale,
                                     const FrameStats& stats, CompositeStats& out);

// The same for the blending methods (compositesInSteps), after this rank's timed frames:
// the depth pass again, the closest depths of all ranks to every rank (MIN), the blend pass against them, the
// blend sums of all ranks to rank 0 (SUM), where the method's resolve and the resolve stage run once: the
// frame of one process. Returns the image on rank 0, nothing elsewhere. A collective.
std::vector<uint32_t> compositeHqsFrame(Renderer& renderer, std::span<const GpuScene* const> scenes,
                                        const Camera& camera, const RenderSettings& settings,
                                        const FrameStats& stats, CompositeStats& out);
// The same with each step drawn by `draw` (lod-hqs: the rank's share of an octree).
std::vector<uint32_t> compositeHqsFrame(Renderer& renderer,
                                        const std::function<FrameStats(const RenderSettings&)>& draw,
                                        const RenderSettings& settings, const FrameStats& stats,
                                        CompositeStats& out);

// The "mpi" object of render --json.
nlohmann::json compositeJson(const CompositeStats& stats);
void printCompositeSummary(const CompositeStats& stats);

} // namespace pointrast::app

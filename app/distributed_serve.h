// `mpirun -np N pointrast serve|view ...` (docs/mpi.md): rank 0 runs the viewer as one process does;
// every frame it draws (a client's frame, a pick's or the overlay's depth frame, a screenshot) is drawn by
// every rank, each its share of the input, and composited on rank 0 as render composites its frame. The
// other ranks open no socket: they follow rank 0's draws until it tells them to stop.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "input.h"
#include "render/renderer.h"
#include "view/scene_source.h"

namespace pointrast::gpu {
class Context;
}

namespace pointrast::app {

// Why a viewer under mpirun does not offer `method` (its frames cannot be composited), or nothing.
std::optional<std::string> viewRefusal(Method method);

// Rank 0's source: its own share drawn and every rank's composited into each frame. `points` counts the
// points of every rank. Its draws are collectives: every other rank runs followDraws().
std::unique_ptr<view::SceneSource>
compositedSource(gpu::Context& context, std::unique_ptr<view::SceneSource> share, uint64_t points);

// The other ranks: draws `share` for every draw of rank 0 until stopFollowers(); returns rank 0's status.
// Throws mpi::JobFailed when a rank failed.
int followDraws(gpu::Context& context, view::SceneSource& share);

// Rank 0, after its viewer stopped: the other ranks end with `status`. A collective.
void stopFollowers(int status);

// How a viewer puts its input on the device (view::web::ServerOptions::makeSource,
// view::ViewerOptions::makeSource).
using SourceMaker = std::function<std::unique_ptr<view::SceneSource>(gpu::Context&, view::SceneInput&,
                                                                     const view::ViewSettings&)>;

// `mpirun -np N pointrast serve|view`: every rank opens its share of the input on its own device (the local
// rank's unless `device` names one; `device` receives the choice); rank 0 runs `viewer` with a SourceMaker
// that draws its share and composites every rank's, the other ranks follow its draws; every rank returns
// rank 0's status. `method` refused under several ranks is an InputError; `settings` are the viewer's.
int runViewerRanks(std::optional<Method> method, std::optional<uint32_t>& device, bool quiet,
                   const view::ViewSettings& settings, const InputSpec& spec, const SceneOptions& scene,
                   const std::function<int(view::SceneInput&, SourceMaker)>& viewer);

} // namespace pointrast::app

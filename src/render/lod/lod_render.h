// A full-detail frame of an octree for `render` and the benchmarks: the whole selection for the camera
// (LodScene::selectAll) made resident before any timed frame, then timed as Renderer::render times a frame
// (warm-up frames, then `frames` frames in one submission, GPU timestamps). A selection larger than the node
// cache is drawn in passes (LodScene::splitPasses), each streamed in and drawn in its own submissions; the
// reported time is then the sum of the passes' GPU time, for one frame.
#pragma once

#include "render/lod/lod_passes.h"
#include "render/lod/lod_scene.h"

namespace pointrast::lod {

struct LodRenderResult {
  FrameStats frame;         // GPU time; frame.batch: the GPU's counts (nodes in the batch fields)
  LodStats lod;             // selection, draw list and streaming
  uint32_t passes = 0;      // passes of the selection (1 when it fits the cache)
  double streamSeconds = 0; // wall time until the selection was resident (every pass's, with several)
};

// The camera's matrix and near plane for the scene's passes.
LodCamera lodCamera(const LodScene& scene, const Camera& camera, uint32_t width, uint32_t height);

LodRenderResult renderOctree(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                             const Camera& camera, const RenderSettings& settings, const LodView& view);

} // namespace pointrast::lod

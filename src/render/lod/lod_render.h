// How the Renderer draws an octree (Renderer::render and renderFrame with a LOD method).
//
// render: a full-detail frame for `render` and the benchmarks. The whole selection for the camera
// (LodScene::selectAll) is made resident before any timed frame, then timed as Renderer::render times a
// frame (warm-up frames, then `frames` frames in one submission, GPU timestamps). A selection larger than
// the node cache is drawn in passes (LodScene::splitPasses), each streamed in and drawn in its own
// submission; the reported time is then the sum of the passes' GPU time, for one frame.
//
// renderResidentFrame: one frame of a viewer (LodScene::update, then the uploads and the frame in one
// submission), never waiting for a reader.
#pragma once

#include <functional>
#include <limits>

#include "render/lod/lod_passes.h"
#include "render/lod/lod_scene.h"

namespace pointrast::lod {

// The matrices (one view, or a stereo frame's two eyes) and near plane for the scene's passes; width x
// height is one view's image.
LodCamera lodCamera(const LodScene& scene, std::span<const Camera> views, uint32_t width, uint32_t height);

// What a frame records after its passes: the resolve stage (Renderer). Either function may be empty.
struct FrameEpilogue {
  static constexpr uint32_t kUntimed = std::numeric_limits<uint32_t>::max();
  // Once, at the start of the submission that records the timed frames, with their number.
  std::function<void(VkCommandBuffer cmd, uint32_t timedFrames)> begin;
  // After each frame's passes: the timed frame's index, or kUntimed for a warm-up frame.
  std::function<void(VkCommandBuffer cmd, uint32_t frame)> record;
};

// How settings choose nodes.
LodView lodView(const RenderSettings& settings);

// `views`: the camera of each half of the targets (targets.eyes of them).
FrameStats renderOctree(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                        std::span<const Camera> views, const RenderSettings& settings,
                        const FrameEpilogue& epilogue);

FrameStats renderResidentFrame(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                               std::span<const Camera> views, const RenderSettings& settings,
                               const FrameEpilogue& epilogue);

} // namespace pointrast::lod

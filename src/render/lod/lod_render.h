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

#include "render/lod/lod_passes.h"
#include "render/lod/lod_scene.h"

namespace pointrast::lod {

// The camera's matrix and near plane for the scene's passes.
LodCamera lodCamera(const LodScene& scene, const Camera& camera, uint32_t width, uint32_t height);

// How settings choose nodes.
LodView lodView(const RenderSettings& settings);

FrameStats renderOctree(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                        const Camera& camera, const RenderSettings& settings);

FrameStats renderResidentFrame(gpu::Context& context, LodScene& scene, LodPasses& passes, Targets& targets,
                               const Camera& camera, const RenderSettings& settings);

} // namespace pointrast::lod

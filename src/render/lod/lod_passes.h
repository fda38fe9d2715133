// The GPU passes of the LOD methods (shaders/lod*.glsl, raster_lod*.comp.glsl): lod draws a draw list's nodes
// with the batch rasterizer's loop into the visibility buffer and resolves colors through the node cache;
// lod-hqs draws depths, then blends with the single 64-bit accumulation and its overflow fallback. A frame is
// one pass over a list (recordFrame), or, for a selection larger than the cache, several passes over lists
// in their own submissions (recordBegin, recordPass per list, recordFinish): lod composes each pass into a
// per-pixel composite under the whole selection's order, lod-hqs keeps its depths and sums across passes, so
// both give the image of one pass.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/glm.hpp>

#include "gpu/buffer.h"
#include "gpu/program.h"
#include "render/lod/lod_scene.h"
#include "render/method.h"

namespace pointrast::lod {

// The frame's camera for the passes: view-projection relative to the scene origin, near plane; a stereo
// frame's right eye in rightViewProj (viewProj is the left's).
struct LodCamera {
  glm::mat4 viewProj{1.0f};
  glm::mat4 rightViewProj{1.0f};
  float nearW = 0;
};

// What a pass of a frame in several passes does.
enum class LodPhase {
  Closest, // lod: draw the pass and compose it into the composite
  Depth,   // lod-hqs, first round over the passes: closest depths
  Blend,   // lod-hqs, second round: blend the points within 1 % of them
};

class LodPasses {
public:
  // The passes of a LOD row of the method table: its shader and specialization constants draw the pages;
  // Blend output (lod-hqs) adds the accumulation pass. width x height is the whole framebuffer; eyes = 2:
  // the stereo passes, each eye in one half.
  LodPasses(gpu::Context& context, const MethodInfo& method, uint32_t width, uint32_t height, uint32_t eyes);
  bool hqs() const { return hqs_; }

  // The list the next recorded commands draw (host-written tables, copied to the GPU by each pass). One list
  // per submission: call between submissions only.
  void setList(const LodDrawList& list);

  // A frame in one pass; lod-hqs records the step of it settings.hqsPass names (renderer.h, HqsPass).
  void recordFrame(VkCommandBuffer cmd, const LodCamera& camera, Targets& targets,
                   const RenderSettings& settings);

  // A frame in several passes: the begin clears what the step `step` of lod-hqs fills (the whole frame's
  // steps for lod).
  void recordBegin(VkCommandBuffer cmd, Targets& targets, HqsPass step = HqsPass::Whole);
  void recordPass(VkCommandBuffer cmd, const LodCamera& camera, Targets& targets,
                  const RenderSettings& settings, LodPhase phase);
  void recordFinish(VkCommandBuffer cmd, Targets& targets, const RenderSettings& settings);

  // Counts since the last recordFrame or recordBegin (nodes in the batch fields), after the submission of
  // recordFrame or recordFinish (which copy them where the host reads them: no submission of its own).
  BatchStats readStats() const;

  // lod-hqs: the blend sums of the last frame (PointMethod::readSums' layout), and sums set for its resolve.
  std::vector<uint64_t> readSums();
  void writeSums(std::span<const uint64_t> sums);

private:
  void writeFrame(const Targets& targets, const LodCamera& camera, const RenderSettings& settings,
                  bool nodeStats);
  void recordTables(VkCommandBuffer cmd);
  void recordStatsCopy(VkCommandBuffer cmd);
  void recordNodes(VkCommandBuffer cmd, const LodCamera& camera);
  void recordPages(VkCommandBuffer cmd, const gpu::ComputeProgram& program, const LodCamera& camera);
  void recordResolve(VkCommandBuffer cmd, const gpu::ComputeProgram& program, const Targets& targets,
                     const RenderSettings& settings, uint64_t aux, bool canonical);

  gpu::Context& context_;
  bool hqs_;
  uint32_t eyes_;
  gpu::ComputeProgram nodes_;
  gpu::ComputeProgram raster_;     // lod, or lod-hqs's depth pass
  gpu::ComputeProgram accumulate_; // lod-hqs
  gpu::ComputeProgram resolve_;    // lod: direct; lod-hqs: resolve_hqs
  gpu::ComputeProgram compose_;    // lod, several passes: into the composite
  gpu::ComputeProgram finish_;     // lod, several passes: the composite into the image
  gpu::Buffer accumulators_;       // lod-hqs
  uint64_t pixels_ = 0;            // of the whole framebuffer
  gpu::Buffer composite_;          // lod, several passes
  gpu::Buffer stats_;
  gpu::Buffer statsReadback_;
  gpu::Buffer upload_; // LodFrame, nodes, pages, written by the host
  gpu::Buffer tables_; // LodFrame, nodes, views, pages on the GPU
  uint64_t capacityNodes_ = 0, capacityPages_ = 0;
  uint32_t nodeCount_ = 0, pageCount_ = 0;
};

} // namespace pointrast::lod

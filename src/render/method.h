// The interface every rendering method implements (internal to src/render). A method owns its programs
// and any buffers beyond the shared targets, and records one whole frame: clear, draw every part of every
// scene, resolve into the RGBA8 image. The Renderer times frames and owns the targets.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/buffer.h"
#include "gpu/program.h"
#include "gpu/shared_types.h"
#include "render/renderer.h"

namespace pointrast {

namespace gpu {
class Context;
}

struct Targets {
  uint32_t width = 0, height = 0; // of the whole framebuffer and image: both eyes of a stereo renderer
  uint32_t eyes = 1;              // 2: two images of width / 2 side by side, left eye first
  uint32_t eyeWidth() const { return width / eyes; }
  gpu::Buffer framebuffer; // 8 B per pixel; methods choose the layout
  gpu::Buffer image;       // RGBA8 per pixel
  gpu::Buffer words;       // canonical depth << 32 | color per pixel, filled when non-empty
  // Host-visible scene table (shared.h, kSceneTableHeader): each visibility part's clip volumes address, then
  // a record per scene: ClipVolumes relative to its origin and its double-precision view-projection.
  gpu::Buffer scenes;
  uint64_t pixels() const { return uint64_t(width) * height; }
};

// Byte offset of scene s's record in Targets::scenes.
inline uint64_t sceneRecordOffset(size_t s) {
  return shared::kSceneTableHeader + uint64_t(s) * shared::kSceneRecordBytes;
}

struct Frame {
  VkCommandBuffer cmd;
  std::span<const GpuScene* const> scenes;
  const Camera& camera;
  const RenderSettings& settings;
  // The camera of each half of the image (one for mono: `camera`; left half first for stereo).
  std::span<const Camera> views;
  // Whether the frame gathers the method's counts (readStats). Renderer::render counts its last timed frame
  // only: the batch methods draw the others with pipelines that count nothing, since counting costs ~5 %
  // of a frame on an H200 (docs/performance.md).
  bool counted = true;
};

class PointMethod {
public:
  virtual ~PointMethod() = default;
  virtual void recordFrame(const Frame& frame, Targets& targets) = 0;
  // Counts of the last frame, for methods that keep them (the batch methods); read after the frame's
  // submission finished.
  virtual std::optional<BatchStats> readStats() { return std::nullopt; }
  // HQS methods (blends() true): the blend sums of Renderer::hqsSums(), two words a pixel, read from or
  // written into the accumulators.
  virtual bool blends() const { return false; }
  virtual std::vector<uint64_t> readSums() { return {}; }
  virtual void writeSums(std::span<const uint64_t>) {}
};

// The blend sums of an HQS accumulator buffer as PointMethod::readSums() returns them (two words a pixel,
// r << 32 | g, b << 32 | count), read from and written into its layout: two words a pixel (hqs), or one
// packed word a pixel before two fallback words a pixel (hqs1r's single atomic, oneRound; also batch-hqs's),
// whose packed 16-bit fields are added into the fallback sums as the resolve adds them.
std::vector<uint64_t> readHqsSums(gpu::Context& context, const gpu::Buffer& accumulators, uint64_t pixels,
                                  bool oneRound);
void writeHqsSums(gpu::Context& context, const gpu::Buffer& accumulators, uint64_t pixels, bool oneRound,
                  std::span<const uint64_t> sums);

// Points per thread of the raster_closest and raster_hqs shaders (POINTS_PER_THREAD): a thread loads 4
// positions before projecting any, four loads in flight instead of one (docs/performance.md has the measurements).
constexpr uint32_t kPointsPerThread = 4;

// Calls draw(push, grid) for every part of every scene, with `base` completed for that part: the matrix
// relative to the scene's origin (float, and the scene's record in targets.scenes), the part's addresses
// and point count, and the workgroup grid. `base` brings the method's framebuffer/aux addresses.
template <class Draw>
void forEachPart(const Frame& frame, const Targets& targets, uint32_t groupSize, shared::RasterPush base,
                 Draw&& draw) {
  double aspect = double(targets.width) / double(targets.height);
  base.width = targets.width;
  base.height = targets.height;
  for (size_t s = 0; s < frame.scenes.size(); ++s) {
    const GpuScene& scene = *frame.scenes[s];
    base.viewProj = glm::mat4(viewProjection(frame.camera, scene.origin(), aspect));
    base.scene = targets.scenes.address() + sceneRecordOffset(s);
    const auto* clip = reinterpret_cast<const shared::ClipVolumes*>(
        static_cast<const char*>(targets.scenes.mapped()) + sceneRecordOffset(s));
    if (clip->mode != shared::kClipNone) base.scene |= shared::kSceneClipped;
    base.nearW = float(frame.camera.nearW > 0 ? frame.camera.nearW : defaultNear(scene.bounds()));
    for (const ScenePart& part : scene.parts()) {
      gpu::Grid grid = gpu::gridFor(part.count, groupSize);
      base.positions = part.positions.address();
      base.colors = part.colors.address();
      base.pointCount = uint32_t(part.count);
      base.groupsX = grid.x;
      draw(base, grid);
    }
  }
}

// Whether the frame's clip volumes drop points (RenderSettings::filter): the methods then draw with their
// CLIP = 1 pipelines (specialization constant kClipConstant of point.inc.glsl).
inline bool clipsPoints(const RenderSettings& settings) {
  return settings.filter.hasClip() && settings.filter.clipMode != ClipMode::Highlight;
}
constexpr uint32_t kClipConstant = 15;

// int40 steps per unit of depth so that 2^40 - 1 steps span [0, farthest bounds corner from the eye].
double int40Scale(std::span<const GpuScene* const> scenes, const Camera& camera);

// The resolve push for the shared targets; words are captured when settings ask for them.
shared::ResolvePush resolvePush(const Frame& frame, const Targets& targets, uint64_t framebuffer,
                                uint32_t groupSize);

// One factory per MethodFamily; each builds its programs from the method's row of the table.
std::unique_ptr<PointMethod> createClosestMethod(gpu::Context& context, const MethodInfo& method,
                                                 DepthMode depth);
std::unique_ptr<PointMethod> createHqsMethod(gpu::Context& context, const MethodInfo& method, uint32_t width,
                                             uint32_t height);
std::unique_ptr<PointMethod> createHwPointsMethod(gpu::Context& context, const MethodInfo& method,
                                                  uint32_t width, uint32_t height);
// eyes = 2: the stereo passes (one read of each point, both halves of the framebuffer).
std::unique_ptr<PointMethod> createBatchMethod(gpu::Context& context, const MethodInfo& method,
                                               uint32_t width, uint32_t height, uint32_t eyes);

} // namespace pointrast

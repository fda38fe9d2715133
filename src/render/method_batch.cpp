// The 2022 batch methods (Schuetz, Kerbl, Wimmer, "Software Rasterization of 2 Billion Points in Real
// Time"): batch and batch-prefetch (raster_batch.comp, then resolve_batch.comp fetching the colors of
// visible points) and batch-hqs (a prefetch depth pass, raster_batch_hqs.comp accumulating, resolve_hqs.comp
// with hqs1r's layout). They read scenes in the batched layout (render/scene.h). Before the drawing passes,
// batch_views.comp computes every batch's box decision once into a buffer that they read. batch-hqs draws
// dense batches (many points a pixel) in one pass instead of two (batch_dense.inc.glsl): beside the depth
// pass, raster_batch_hqs_dense.comp blends them at once; hqs_dense_check.comp then takes back the pixels
// where that was wrong, and the accumulation pass blends their dense points again with the usual test.
#include <algorithm>
#include <cstring>

#include "base/error.h"
#include "gpu/context.h"
#include "render/batch_stats.h"
#include "render/method.h"

namespace pointrast {

namespace {

// Calls draw(push, batches) for every part of every scene, numbering parts in draw order: the number is
// the part's visibility part (shared.h), and the index of its colors in BatchFrame::partColors. Batches are
// numbered over the frame too (BatchPush::firstView).
template <class Draw>
void forEachBatchPart(const Frame& frame, const Targets& targets, uint64_t frameAddress, Draw&& draw) {
  const double aspect = double(targets.eyeWidth()) / double(targets.height);
  shared::BatchPush push{};
  push.frame = frameAddress;
  uint32_t number = 0;
  uint32_t batches = 0;
  for (const GpuScene* scene : frame.scenes) {
    // The matrix and near plane of forEachPart(): the same projection as the 2021 methods (the left eye's
    // for stereo; the right eye's is in the frame).
    push.viewProj = glm::mat4(viewProjection(frame.views[0], scene->origin(), aspect));
    push.nearW = float(frame.camera.nearW > 0 ? frame.camera.nearW : defaultNear(scene->bounds()));
    for (const ScenePart& part : scene->parts()) {
      push.high = part.high.address();
      push.medium = part.medium.address();
      push.low = part.low.address();
      push.bounds = part.batches.address();
      push.colors = part.colors.address();
      push.pointCount = uint32_t(part.count);
      push.part = number++;
      push.firstView = batches;
      batches += uint32_t(part.batchCount());  // <= 64 parts x kMaxPartBatches
      draw(push, uint32_t(part.batchCount())); // <= kMaxPartBatches: one row of workgroups
    }
  }
}

// Dense tiles (shared.h, kHqsDenseTile) along n pixels.
uint32_t tilesAcross(uint32_t n) {
  return (n + shared::kHqsDenseTile - 1) / shared::kHqsDenseTile;
}

// The batches of a frame's scenes.
uint64_t frameBatches(const Frame& frame) {
  uint64_t batches = 0;
  for (const GpuScene* scene : frame.scenes)
    for (const ScenePart& part : scene->parts())
      batches += part.batchCount();
  return batches;
}

class BatchMethod : public PointMethod {
public:
  BatchMethod(gpu::Context& context, const MethodInfo& method, uint32_t width, uint32_t height, uint32_t eyes)
      : context_(context), hqs_(method.output == MethodOutput::Blend), eyes_(eyes),
        pixels_(uint64_t(width) * height) {
    // The row's constants: PREFETCH (one 128-bit load of 4 consecutive points) and, for the blending
    // rows, DEPTH_ONLY (the depth pass before the accumulation); STEREO for two eyes.
    // COUNT (batch.inc.glsl): the pipelines of counted frames gather the statistics, the others do not.
    const gpu::SpecConstant stereo{/* STEREO= */ 2, eyes == 2 ? 1u : 0u};
    const gpu::SpecConstant uncounted{kCountId, 0};
    raster_ = gpu::ComputeProgram(context, method.shader, method.spec.with({stereo}));
    rasterUncounted_ = gpu::ComputeProgram(context, method.shader, method.spec.with({stereo, uncounted}));
    views_ = gpu::ComputeProgram(context, "batch_views.comp");
    if (hqs_) {
      accumulate_ = gpu::ComputeProgram(context, "raster_batch_hqs.comp", {stereo});
      accumulateUncounted_ = gpu::ComputeProgram(context, "raster_batch_hqs.comp", {stereo, uncounted});
      if (eyes == 1) {
        dense_ = gpu::ComputeProgram(context, "raster_batch_hqs_dense.comp");
        denseUncounted_ = gpu::ComputeProgram(context, "raster_batch_hqs_dense.comp", {uncounted});
        check_ = gpu::ComputeProgram(context, "hqs_dense_check.comp");
        checkUncounted_ = gpu::ComputeProgram(context, "hqs_dense_check.comp", {uncounted});
      }
      resolve_ = gpu::ComputeProgram(context, "resolve_hqs.comp", {{/* ONE_ROUND= */ 0, 1}});
      // hqs1r's accumulators (1 packed + 2 fallback uint64 per pixel), then the dense batches' farthest
      // depths (uint per pixel) and flagged tiles (uint per tile).
      const uint64_t pixels = uint64_t(width) * height;
      const uint64_t tiles = uint64_t(tilesAcross(width)) * tilesAcross(height);
      accumulators_ = gpu::Buffer(context, pixels * 28 + tiles * 4, gpu::kBufferUsage, gpu::MemoryKind::Device,
                                  "batch-hqs accumulators");
    } else {
      resolve_ = gpu::ComputeProgram(context, "resolve_batch.comp");
    }
    frame_ = gpu::Buffer(context, sizeof(shared::BatchFrame), gpu::kBufferUsage, gpu::MemoryKind::Device,
                         "batch frame");
    frameUpload_ = gpu::Buffer(context, sizeof(shared::BatchFrame), VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                               gpu::MemoryKind::Upload, "batch frame upload");
    stats_ =
        gpu::Buffer(context, kStatsBytes, gpu::kBufferUsage, gpu::MemoryKind::Device, "batch statistics");
  }

  void recordFrame(const Frame& frame, Targets& targets) override {
    VkCommandBuffer cmd = frame.cmd;
    const uint64_t pixels = targets.pixels();
    // The frame's constants, written here (before the submission) and copied into device memory at the
    // start of the frame: sizeof(shared::BatchFrame) bytes, which every workgroup reads from the GPU's
    // caches.
    // batch-hqs in steps (HqsPass, frames composited across processes): the depth pass, the accumulation
    // against depths set from outside, the resolve of sums set from outside. The steps draw without the
    // dense path, which blends dense batches against this frame's own depths during its depth pass; a
    // whole frame with it is the same image (RenderSettings::batchHqsDense).
    const HqsPass pass = hqs_ ? frame.settings.hqsPass : HqsPass::Whole;
    const bool whole = pass == HqsPass::Whole, depthPass = whole || pass == HqsPass::Depth;
    const bool blendPass = hqs_ && (whole || pass == HqsPass::Blend);
    shared::BatchFrame f{};
    f.framebuffer = targets.framebuffer.address();
    f.stats = stats_.address();
    f.accumulators = hqs_ ? accumulators_.address() : 0;
    f.denseDepths = hqs_ ? accumulators_.address() + pixels * 24 : 0;
    f.denseTiles = hqs_ ? accumulators_.address() + pixels * 28 : 0;
    f.dense = hqs_ && eyes_ == 1 && frame.settings.batchHqsDense && whole ? 1 : 0;
    f.tilesX = tilesAcross(targets.width);
    f.denseHistory = f.dense != 0 ? historyBuffer(frame, cmd).address() : 0;
    f.width = targets.eyeWidth();
    f.height = targets.height;
    f.forcedWords = frame.settings.precision;
    f.culling = frame.settings.batchCulling ? 1 : 0;
    f.pitch = targets.width;
    f.eyes = eyes_;
    f.views = viewBuffer(frame).address();
    f.clips = targets.scenes.address();
    const double aspect = double(targets.eyeWidth()) / double(targets.height);
    uint32_t part = 0;
    for (const GpuScene* scene : frame.scenes) {
      const glm::mat4 right =
          eyes_ == 2 ? glm::mat4(viewProjection(frame.views[1], scene->origin(), aspect)) : glm::mat4(1.0f);
      for (const ScenePart& p : scene->parts()) {
        f.rightViewProj[part] = right;
        f.partColors[part++] = p.colors.address(); // Renderer::render checked part <= 64
      }
    }
    std::memcpy(frameUpload_.mapped(), &f, sizeof f);
    VkBufferCopy copy{0, 0, sizeof f};
    gpu::vkCmdCopyBuffer(cmd, frameUpload_.handle(), frame_.handle(), 1, &copy);
    if (depthPass) // kEmptyPixel
      gpu::vkCmdFillBuffer(cmd, targets.framebuffer.handle(), 0, pixels * 8, 0xFFFFFFFFu);
    gpu::vkCmdFillBuffer(cmd, stats_.handle(), 0, VK_WHOLE_SIZE, 0);
    if (blendPass) gpu::vkCmdFillBuffer(cmd, accumulators_.handle(), 0, VK_WHOLE_SIZE, 0);
    gpu::fullBarrier(cmd);
    if (depthPass || blendPass) {
      forEachBatchPart(
          frame, targets, frame_.address(), [&](const shared::BatchPush& push, uint32_t batches) {
            views_.dispatch(cmd, (batches + views_.groupSize() - 1) / views_.groupSize(), 1, push);
          });
      gpu::fullBarrier(cmd);
    }
    const gpu::ComputeProgram& raster = frame.counted ? raster_ : rasterUncounted_;
    if (depthPass)
      forEachBatchPart(
          frame, targets, frame_.address(),
          [&](const shared::BatchPush& push, uint32_t batches) { raster.dispatch(cmd, batches, 1, push); });
    if (f.dense != 0) {
      // Beside the depth pass (both only take minima and add): dense batches in one pass, then the check.
      const gpu::ComputeProgram& dense = frame.counted ? dense_ : denseUncounted_;
      forEachBatchPart(frame, targets, frame_.address(), [&](const shared::BatchPush& push, uint32_t batches) {
        dense.dispatch(cmd, batches, 1, push);
      });
      gpu::fullBarrier(cmd);
      shared::BatchPush push{};
      push.frame = frame_.address();
      const gpu::ComputeProgram& check = frame.counted ? check_ : checkUncounted_;
      const auto grid = gpu::gridFor(pixels, check.groupSize());
      check.dispatch(cmd, grid.x, grid.y, push);
    }
    gpu::fullBarrier(cmd);
    shared::ResolvePush resolve =
        resolvePush(frame, targets, targets.framebuffer.address(), resolve_.groupSize());
    if (blendPass) {
      forEachBatchPart(frame, targets, frame_.address(),
                       [&](const shared::BatchPush& push, uint32_t batches) {
                         (frame.counted ? accumulate_ : accumulateUncounted_).dispatch(cmd, batches, 1, push);
                       });
      gpu::fullBarrier(cmd);
    }
    resolve.aux = hqs_ ? accumulators_.address() : frame_.address(); // or the table of color buffers
    if (whole || pass == HqsPass::Resolve) {
      resolve_.dispatch(cmd, resolve.groupsX, gpu::gridFor(pixels, resolve_.groupSize()).y, resolve);
      gpu::fullBarrier(cmd);
    }
  }

  bool blends() const override { return hqs_; }
  // hqs1r's accumulator layout (the first 24 bytes a pixel).
  std::vector<uint64_t> readSums() override { return readHqsSums(context_, accumulators_, pixels_, true); }
  void writeSums(std::span<const uint64_t> sums) override {
    writeHqsSums(context_, accumulators_, pixels_, true, sums);
  }

  std::optional<BatchStats> readStats() override {
    uint64_t rows[shared::kBatchStatSlots][shared::kBatchStatCount];
    gpu::readBuffer(context_, stats_, 0, rows, sizeof rows);
    return batchStatsFromRows(rows, hqs_);
  }

private:
  // BatchFrame::views, grown to the frame's batches. The frames of one submission draw the same scenes, so
  // it never changes under a recorded frame.
  const gpu::Buffer& viewBuffer(const Frame& frame) {
    const uint64_t bytes = std::max<uint64_t>(1, frameBatches(frame)) * eyes_ * sizeof(shared::LodNodeView);
    if (!viewRecords_ || viewRecords_.size() < bytes)
      viewRecords_ =
          gpu::Buffer(context_, bytes, gpu::kBufferUsage, gpu::MemoryKind::Device, "batch box decisions");
    return viewRecords_;
  }

  // BatchFrame::denseHistory, grown to the frame's batches and cleared when made (like viewBuffer, it never
  // changes under a recorded frame).
  const gpu::Buffer& historyBuffer(const Frame& frame, VkCommandBuffer cmd) {
    const uint64_t bytes = 4 * (1 + frameBatches(frame));
    if (!history_ || history_.size() < bytes) {
      history_ =
          gpu::Buffer(context_, bytes, gpu::kBufferUsage, gpu::MemoryKind::Device, "batch-hqs dense history");
      gpu::vkCmdFillBuffer(cmd, history_.handle(), 0, VK_WHOLE_SIZE, 0); // before the frame's first barrier
    }
    return history_;
  }

  static constexpr uint64_t kStatsBytes = uint64_t(shared::kBatchStatSlots) * shared::kBatchStatCount * 8;
  gpu::Context& context_;
  bool hqs_;
  uint32_t eyes_;
  uint64_t pixels_;                       // of the whole image (both eyes)
  static constexpr uint32_t kCountId = 5; // COUNT
  gpu::ComputeProgram raster_;     // batch / batch-prefetch, or batch-hqs's depth pass
  gpu::ComputeProgram rasterUncounted_;
  gpu::ComputeProgram views_;      // batch_views.comp
  gpu::ComputeProgram accumulate_; // batch-hqs
  gpu::ComputeProgram accumulateUncounted_;
  gpu::ComputeProgram dense_; // batch-hqs, mono: the dense batches' first pass and the per-pixel check
  gpu::ComputeProgram denseUncounted_;
  gpu::ComputeProgram check_;
  gpu::ComputeProgram checkUncounted_;
  gpu::ComputeProgram resolve_;
  gpu::Buffer accumulators_; // batch-hqs
  gpu::Buffer viewRecords_;  // shared::LodNodeView per batch and eye (BatchFrame::views)
  gpu::Buffer history_;      // batch-hqs: BatchFrame::denseHistory
  gpu::Buffer frame_;        // shared::BatchFrame, device-local
  gpu::Buffer frameUpload_;  // its host-written source
  gpu::Buffer stats_;        // uint64_t[kBatchStatSlots][kBatchStatCount]
};

} // namespace

std::unique_ptr<PointMethod> createBatchMethod(gpu::Context& context, const MethodInfo& method,
                                               uint32_t width, uint32_t height, uint32_t eyes) {
  return std::make_unique<BatchMethod>(context, method, width, height, eyes);
}

} // namespace pointrast

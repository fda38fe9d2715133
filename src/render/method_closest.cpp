// The closest-point families: one raster shader per point and one resolve. MethodFamily::Closest (atomicmin,
// earlyz, reduce, dedup, justset... : the row's shader with its specialization constants) and
// MethodFamily::BusyLoop (the per-pixel lock, which keeps depth and color in two uint arrays).
#include <optional>

#include "base/error.h"
#include "gpu/context.h"
#include "render/method.h"

namespace pointrast {

namespace {

// Resolve LAYOUT (resolve.comp): 64-bit words with float depth, with int40 depth, or busyloop's two
// uint arrays.
constexpr uint32_t kResolveFloat = 0, kResolveInt40 = 1, kResolveLockArrays = 2;

class ClosestMethod : public PointMethod {
public:
  ClosestMethod(gpu::Context& context, const MethodInfo& method, DepthMode depth)
      : context_(context), method_(method), depth_(depth),
        lockArrays_(method.family == MethodFamily::BusyLoop) {
    raster_ = rasterProgram(false);
    pointsPerGroup_ = raster_.groupSize() * (lockArrays_ ? 1 : kPointsPerThread);
    const uint32_t layout = lockArrays_                 ? kResolveLockArrays
                            : depth == DepthMode::Int40 ? kResolveInt40
                                                        : kResolveFloat;
    resolve_ = gpu::ComputeProgram(context, "resolve.comp", {{/* LAYOUT= */ 0, layout}});
  }

  void recordFrame(const Frame& frame, Targets& targets) override {
    VkCommandBuffer cmd = frame.cmd;
    uint64_t pixels = targets.pixels();
    if (lockArrays_) {
      // Two uint arrays: depth (empty = kEmptyDepthBits, unlocked) then color.
      gpu::vkCmdFillBuffer(cmd, targets.framebuffer.handle(), 0, pixels * 4, shared::kEmptyDepthBits);
      gpu::vkCmdFillBuffer(cmd, targets.framebuffer.handle(), pixels * 4, pixels * 4, 0xFFFFFFFFu);
    } else {
      gpu::vkCmdFillBuffer(cmd, targets.framebuffer.handle(), 0, pixels * 8, 0xFFFFFFFFu); // kEmptyPixel
    }
    gpu::fullBarrier(cmd);
    shared::RasterPush base{};
    base.framebuffer = targets.framebuffer.address();
    base.depthScale = float(frame.settings.depthScale);
    if (clipsPoints(frame.settings) && !clipRaster_)
      clipRaster_ = rasterProgram(true); // made once, when needed
    const gpu::ComputeProgram& raster = clipsPoints(frame.settings) ? *clipRaster_ : raster_;
    forEachPart(frame, targets, pointsPerGroup_, base, [&](const shared::RasterPush& push, gpu::Grid grid) {
      raster.dispatch(cmd, grid.x, grid.y, push);
    });
    gpu::fullBarrier(cmd);
    shared::ResolvePush resolve =
        resolvePush(frame, targets, targets.framebuffer.address(), resolve_.groupSize());
    resolve_.dispatch(cmd, resolve.groupsX, gpu::gridFor(pixels, resolve_.groupSize()).y, resolve);
    gpu::fullBarrier(cmd);
  }

private:
  // The row's raster shader; `clip`: the variant that tests the clip volumes.
  gpu::ComputeProgram rasterProgram(bool clip) {
    const uint32_t clipValue = clip ? 1u : 0u;
    if (lockArrays_) {
      // No release ordering on CPU devices: see the shader for why lavapipe needs that.
      const uint32_t release = context_.info().software() ? 0u : 1u;
      return gpu::ComputeProgram(
          context_, method_.shader,
          method_.spec.with({{/* RELEASE= */ 0, release}, {kClipConstant, clipValue}}));
    }
    return gpu::ComputeProgram(
        context_, depth_ == DepthMode::Int40 ? method_.int40Shader : method_.shader,
        method_.spec.with({{/* POINTS_PER_THREAD= */ 4, kPointsPerThread}, {kClipConstant, clipValue}}));
  }

  gpu::Context& context_;
  MethodInfo method_;
  DepthMode depth_;
  bool lockArrays_; // busyloop: depth array then color array, not 64-bit words
  gpu::ComputeProgram raster_;
  std::optional<gpu::ComputeProgram> clipRaster_; // made on the first frame that clips
  gpu::ComputeProgram resolve_;
  uint32_t pointsPerGroup_ = 0; // points one workgroup of raster_ draws
};

} // namespace

std::unique_ptr<PointMethod> createClosestMethod(gpu::Context& context, const MethodInfo& method,
                                                 DepthMode depth) {
  return std::make_unique<ClosestMethod>(context, method, depth);
}

} // namespace pointrast

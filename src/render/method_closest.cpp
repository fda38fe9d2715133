// The closest-point families: one raster shader per point and one resolve. MethodFamily::Closest (atomicmin,
// earlyz, reduce, dedup, justset... : the row's shader with its specialization constants) and
// MethodFamily::BusyLoop (the per-pixel lock, which keeps depth and color in two uint arrays).
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
      : lockArrays_(method.family == MethodFamily::BusyLoop) {
    const bool int40 = depth == DepthMode::Int40;
    if (lockArrays_) {
      // No release ordering on CPU devices: see the shader for why lavapipe needs that.
      const uint32_t release = context.info().software() ? 0u : 1u;
      raster_ = gpu::ComputeProgram(context, method.shader, method.spec.with({{/* RELEASE= */ 0, release}}));
      pointsPerGroup_ = raster_.groupSize();
    } else {
      raster_ = gpu::ComputeProgram(context, int40 ? method.int40Shader : method.shader,
                                    method.spec.with({{/* POINTS_PER_THREAD= */ 4, kPointsPerThread}}));
      pointsPerGroup_ = raster_.groupSize() * kPointsPerThread;
    }
    const uint32_t layout = lockArrays_ ? kResolveLockArrays : int40 ? kResolveInt40 : kResolveFloat;
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
    forEachPart(frame, targets, pointsPerGroup_, base, [&](const shared::RasterPush& push, gpu::Grid grid) {
      raster_.dispatch(cmd, grid.x, grid.y, push);
    });
    gpu::fullBarrier(cmd);
    shared::ResolvePush resolve =
        resolvePush(frame, targets, targets.framebuffer.address(), resolve_.groupSize());
    resolve_.dispatch(cmd, resolve.groupsX, gpu::gridFor(pixels, resolve_.groupSize()).y, resolve);
    gpu::fullBarrier(cmd);
  }

private:
  bool lockArrays_; // busyloop: depth array then color array, not 64-bit words
  gpu::ComputeProgram raster_;
  gpu::ComputeProgram resolve_;
  uint32_t pointsPerGroup_ = 0; // points one workgroup of raster_ draws
};

} // namespace

std::unique_ptr<PointMethod> createClosestMethod(gpu::Context& context, const MethodInfo& method,
                                                 DepthMode depth) {
  return std::make_unique<ClosestMethod>(context, method, depth);
}

} // namespace pointrast

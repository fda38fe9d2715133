// The closest-point methods: atomicmin, earlyz, reduce, reduce-earlyz, dedup (NV and ballot), justset
// (raster_closest*.comp with specialization constants) and busyloop (its own shader and layout).
#include "base/error.h"
#include "gpu/context.h"
#include "render/method.h"

namespace pointrast {

namespace {

class ClosestMethod : public PointMethod {
public:
  ClosestMethod(gpu::Context& context, Method method, DepthMode depth) : method_(method), depth_(depth) {
    bool int40 = depth == DepthMode::Int40;
    uint32_t earlyZ = method == Method::EarlyZ || method == Method::ReduceEarlyZ || method == Method::Dedup ||
                      method == Method::DedupBallot;
    uint32_t reduce = method == Method::Reduce || method == Method::ReduceEarlyZ ? 1
                      : method == Method::DedupBallot                            ? 2
                                                                                 : 0;
    uint32_t justSet = method == Method::JustSet;
    if (method == Method::BusyLoop) {
      // No release ordering on CPU devices: see the shader for why lavapipe needs that.
      uint32_t release = context.info().software() ? 0u : 2u;
      raster_ = gpu::ComputeProgram(context, "raster_busyloop.comp", {{/* RELEASE= */ 0, release}});
      pointsPerGroup_ = raster_.groupSize();
    } else if (method == Method::Dedup) {
      // The NV variant partitions instead of reducing: it has no REDUCE constant.
      raster_ = gpu::ComputeProgram(context, int40 ? "raster_dedup_nv_int40.comp" : "raster_dedup_nv.comp",
                                    {{/* EARLY_Z= */ 0, earlyZ},
                                     {/* JUST_SET= */ 2, justSet},
                                     {/* POINTS_PER_THREAD= */ 4, kPointsPerThread}});
      pointsPerGroup_ = raster_.groupSize() * kPointsPerThread;
    } else {
      raster_ = gpu::ComputeProgram(context, int40 ? "raster_closest_int40.comp" : "raster_closest.comp",
                                    {{/* EARLY_Z= */ 0, earlyZ},
                                     {/* REDUCE= */ 1, reduce},
                                     {/* JUST_SET= */ 2, justSet},
                                     {/* POINTS_PER_THREAD= */ 4, kPointsPerThread}});
      pointsPerGroup_ = raster_.groupSize() * kPointsPerThread;
    }
    uint32_t layout = method == Method::BusyLoop ? 2 : int40 ? 1 : 0;
    resolve_ = gpu::ComputeProgram(context, "resolve.comp", {{/* LAYOUT= */ 0, layout}});
  }

  void recordFrame(const Frame& frame, Targets& targets) override {
    VkCommandBuffer cmd = frame.cmd;
    uint64_t pixels = targets.pixels();
    if (method_ == Method::BusyLoop) {
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
  Method method_;
  DepthMode depth_;
  gpu::ComputeProgram raster_;
  gpu::ComputeProgram resolve_;
  uint32_t pointsPerGroup_ = 0; // points one workgroup of raster_ draws
};

} // namespace

std::unique_ptr<PointMethod> createClosestMethod(gpu::Context& context, Method method, DepthMode depth) {
  return std::make_unique<ClosestMethod>(context, method, depth);
}

} // namespace pointrast

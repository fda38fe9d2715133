// High-quality splatting: a depth pass (the early-z closest-point shader), an accumulation pass that
// blends every point within 1 % of the closest depth, and a resolve that divides.
#include <algorithm>
#include <optional>
#include <vector>

#include "base/error.h"
#include "gpu/context.h"
#include "render/method.h"

namespace pointrast {

namespace {

// ONE_ROUND (id 0) of the row: hqs1r's packed single atomic and its accumulator layout.
bool oneRound(const MethodInfo& method) {
  for (const gpu::SpecConstant& s : method.spec.span())
    if (s.id == 0) return s.value != 0;
  return false;
}

// Points per thread of raster_hqs.comp (fixed in the shader).
constexpr uint32_t kAccumulatePointsPerThread = 4;

class HqsMethod : public PointMethod {
public:
  HqsMethod(gpu::Context& context, const MethodInfo& method, uint32_t width, uint32_t height)
      : context_(context), method_(method), oneRound_(oneRound(method)), pixels_(uint64_t(width) * height) {
    const uint64_t pixels = pixels_;
    // hqs: 2 uint64 sums per pixel. hqs1r: 1 packed uint64 + 2 uint64 fallback sums per pixel.
    accumulators_ =
        gpu::Buffer(context, pixels * 8 * (oneRound_ ? 3 : 2), gpu::kBufferUsage, gpu::MemoryKind::Device,
                    oneRound_ ? "hqs1r accumulators" : "hqs accumulators");
    // The depth pass is the fastest closest-point shader on the H200 (reduce-earlyz, 4 points per thread;
    // docs/performance.md), reading positions only.
    // The accumulation pass draws 4 consecutive points per thread (its loads: three vec4s of positions),
    // its workgroups' chunks interleaved (raster_hqs.comp, hqs_accumulate.inc.glsl).
    passes_[0] = makePasses(false);
    // The resolve reads the accumulators in the layout ONE_ROUND chose (the same constant id).
    resolve_ = gpu::ComputeProgram(context, "resolve_hqs.comp", method.spec.span());
  }

  void recordFrame(const Frame& frame, Targets& targets) override {
    VkCommandBuffer cmd = frame.cmd;
    uint64_t pixels = targets.pixels();
    const HqsPass pass = frame.settings.hqsPass;
    const bool whole = pass == HqsPass::Whole;
    if (whole || pass == HqsPass::Depth)
      gpu::vkCmdFillBuffer(cmd, targets.framebuffer.handle(), 0, pixels * 8, 0xFFFFFFFFu);
    if (whole || pass == HqsPass::Blend)
      gpu::vkCmdFillBuffer(cmd, accumulators_.handle(), 0, VK_WHOLE_SIZE, 0);
    gpu::fullBarrier(cmd);
    shared::RasterPush base{};
    base.framebuffer = targets.framebuffer.address();
    base.aux = accumulators_.address();
    // The CLIP = 1 pair, made on the first frame that clips.
    const bool clip = clipsPoints(frame.settings);
    if (clip && !passes_[1]) passes_[1] = makePasses(true);
    const gpu::ComputeProgram& depth = passes_[clip]->depth;
    const gpu::ComputeProgram& accumulate = passes_[clip]->accumulate;
    if (whole || pass == HqsPass::Depth) {
      forEachPart(
          frame, targets, depth.groupSize() * kPointsPerThread, base,
          [&](const shared::RasterPush& push, gpu::Grid grid) { depth.dispatch(cmd, grid.x, grid.y, push); });
      gpu::fullBarrier(cmd);
    }
    if (whole || pass == HqsPass::Blend) {
      forEachPart(frame, targets, accumulate.groupSize() * kAccumulatePointsPerThread, base,
                  [&](const shared::RasterPush& push, gpu::Grid grid) {
                    // Each part's buffers are allocations of their own, aligned beyond 16 B on every driver;
                    // the shader's vec4 loads rely on it.
                    if ((push.positions | push.colors) % 16 != 0)
                      throw InternalError("internal error: HQS point buffers not 16-byte aligned");
                    accumulate.dispatch(cmd, grid.x, grid.y, push);
                  });
      gpu::fullBarrier(cmd);
    }
    if (whole || pass == HqsPass::Resolve) {
      shared::ResolvePush resolve =
          resolvePush(frame, targets, targets.framebuffer.address(), resolve_.groupSize());
      resolve.aux = accumulators_.address();
      resolve_.dispatch(cmd, resolve.groupsX, gpu::gridFor(pixels, resolve_.groupSize()).y, resolve);
      gpu::fullBarrier(cmd);
    }
  }

  bool blends() const override { return true; }

  std::vector<uint64_t> readSums() override {
    return readHqsSums(context_, accumulators_, pixels_, oneRound_);
  }

  void writeSums(std::span<const uint64_t> sums) override {
    writeHqsSums(context_, accumulators_, pixels_, oneRound_, sums);
  }

private:
  struct Passes {
    gpu::ComputeProgram depth;
    gpu::ComputeProgram accumulate;
  };
  Passes makePasses(bool clip) {
    const uint32_t clipValue = clip ? 1u : 0u;
    Passes p;
    p.depth = gpu::ComputeProgram(context_, "raster_closest.comp",
                                  {{/* EARLY_Z= */ 0, 1},
                                   {/* REDUCE= */ 1, 1},
                                   {/* DEPTH_ONLY= */ 3, 1},
                                   {/* POINTS_PER_THREAD= */ 4, kPointsPerThread},
                                   {kClipConstant, clipValue}});
    p.accumulate =
        gpu::ComputeProgram(context_, method_.shader, method_.spec.with({{kClipConstant, clipValue}}));
    return p;
  }

  gpu::Context& context_;
  MethodInfo method_;
  bool oneRound_;
  uint64_t pixels_;
  gpu::Buffer accumulators_;
  std::optional<Passes> passes_[2]; // without and with the clip test (CLIP)
  gpu::ComputeProgram resolve_;
};

} // namespace

// hqs keeps the two words a pixel as they are; hqs1r's packed 16-bit fields are added into its fallback
// sums, as its resolve adds them.
std::vector<uint64_t> readHqsSums(gpu::Context& context, const gpu::Buffer& accumulators, uint64_t pixels,
                                  bool oneRound) {
  std::vector<uint64_t> sums(2 * pixels);
  if (!oneRound) {
    gpu::readBuffer(context, accumulators, 0, sums.data(), sums.size() * 8);
    return sums;
  }
  std::vector<uint64_t> packed(pixels);
  gpu::readBuffer(context, accumulators, 0, packed.data(), pixels * 8);
  gpu::readBuffer(context, accumulators, pixels * 8, sums.data(), sums.size() * 8);
  for (uint64_t i = 0; i < pixels; ++i) {
    const uint64_t p = packed[i];
    sums[2 * i] += ((p & 0xFFFFu) << 32) + ((p >> 16) & 0xFFFFu);
    sums[2 * i + 1] += (((p >> 32) & 0xFFFFu) << 32) + (p >> 48);
  }
  return sums;
}

void writeHqsSums(gpu::Context& context, const gpu::Buffer& accumulators, uint64_t pixels, bool oneRound,
                  std::span<const uint64_t> sums) {
  if (sums.size() != 2 * pixels) throw InternalError("internal error: HQS sums of another image size");
  if (!oneRound) {
    gpu::writeBuffer(context, accumulators, 0, sums.data(), sums.size() * 8);
    return;
  }
  std::vector<uint64_t> all(3 * pixels, 0); // packed words empty, everything in the fallback sums
  std::copy(sums.begin(), sums.end(), all.begin() + static_cast<ptrdiff_t>(pixels));
  gpu::writeBuffer(context, accumulators, 0, all.data(), all.size() * 8);
}

std::unique_ptr<PointMethod> createHqsMethod(gpu::Context& context, const MethodInfo& method, uint32_t width,
                                             uint32_t height) {
  return std::make_unique<HqsMethod>(context, method, width, height);
}

} // namespace pointrast

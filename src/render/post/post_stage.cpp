#include "render/post/post_stage.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "gpu/timer.h"

namespace pointrast {

namespace {

uint32_t tiles(uint32_t pixels) {
  return (pixels + shared::kPostTile - 1) / shared::kPostTile;
}

} // namespace

PointShape parsePointShape(std::string_view name) {
  if (name == "square") return PointShape::Square;
  if (name == "disc") return PointShape::Disc;
  throw InputError("unknown point shape '" + std::string(name) + "'; choose square or disc");
}

PointSizeMode parsePointSizeMode(std::string_view name) {
  if (name == "fixed") return PointSizeMode::Fixed;
  if (name == "attenuated") return PointSizeMode::Attenuated;
  if (name == "adaptive") return PointSizeMode::Adaptive;
  throw InputError("unknown point size mode '" + std::string(name) +
                   "'; choose fixed, attenuated or adaptive");
}

const char* pointShapeName(PointShape shape) {
  return shape == PointShape::Disc ? "disc" : "square";
}

const char* pointSizeModeName(PointSizeMode mode) {
  switch (mode) {
  case PointSizeMode::Attenuated:
    return "attenuated";
  case PointSizeMode::Adaptive:
    return "adaptive";
  default:
    return "fixed";
  }
}

void validatePostSettings(const PostSettings& s) {
  const float maxSize = float(shared::kMaxPointSize);
  auto sizeOk = [&](float v) { return v >= 1.0f && v <= maxSize; }; // false for NaN
  if (!sizeOk(s.pointSize))
    throw InputError("point size " + std::to_string(s.pointSize) + " is out of range (1.." +
                     std::to_string(shared::kMaxPointSize) + " pixels)");
  if (!sizeOk(s.maxPointSize))
    throw InputError("largest point size " + std::to_string(s.maxPointSize) + " is out of range (1.." +
                     std::to_string(shared::kMaxPointSize) + " pixels)");
  if (s.sizeMode == PointSizeMode::Adaptive)
    throw InputError("adaptive point sizes (from the spacing of each point's LOD level) are not available; "
                     "use fixed or attenuated");
  if (s.dilate > shared::kMaxDilateRadius)
    throw InputError("dilation radius " + std::to_string(s.dilate) + " is out of range (0.." +
                     std::to_string(shared::kMaxDilateRadius) + " pixels)");
  if (!(s.edlStrength >= 0.0f && std::isfinite(s.edlStrength)))
    throw InputError("eye-dome lighting strength must be a finite number >= 0");
  if (!(s.edlRadius > 0.0f && s.edlRadius <= 16.0f))
    throw InputError("eye-dome lighting radius must be in (0, 16] pixels");
}

PostStage::PostStage(gpu::Context& context)
    : context_(context), dilate_(context, "post_dilate.comp"), compose_(context, "post_compose.comp") {}

PostStage::~PostStage() = default;

gpu::Buffer& PostStage::scratch(int index, uint64_t pixels) {
  gpu::Buffer& b = scratch_[index];
  if (!b || b.size() < pixels * 8)
    b = gpu::Buffer(context_, pixels * 8, gpu::kBufferUsage, gpu::MemoryKind::Device,
                    "post words " + std::to_string(index));
  return b;
}

const gpu::ComputeProgram& PostStage::splat(Splat variant) {
  gpu::ComputeProgram& program = splat_[size_t(variant)];
  if (!program.name().empty()) return program;
  const bool disc = variant == Splat::DiscWindow || variant == Splat::DiscScatter;
  const bool attenuated = variant == Splat::SquareScatter || variant == Splat::DiscScatter; // scattered
  const uint32_t axis = variant == Splat::SquareRows ? 1 : variant == Splat::SquareColumns ? 2 : 0;
  program = gpu::ComputeProgram(context_, "post_splat.comp",
                                {{/* SHAPE= */ 0, disc ? shared::kPointShapeDisc : shared::kPointShapeSquare},
                                 {/* ATTENUATED= */ 1, uint32_t(attenuated)},
                                 {/* AXIS= */ 2, axis}});
  return program;
}

void PostStage::record(VkCommandBuffer cmd, const PostView& view, const PostSettings& settings,
                       gpu::TimestampPool* timestamps, uint32_t firstSpan) {
  record(cmd, std::span<const PostView>(&view, 1), settings, timestamps, firstSpan);
}

void PostStage::record(VkCommandBuffer cmd, std::span<const PostView> views, const PostSettings& settings,
                       gpu::TimestampPool* timestamps, uint32_t firstSpan) {
  assert(!views.empty() && views.size() <= kMaxPostViews);
  const PostView& first = views[0];
  for ([[maybe_unused]] const PostView& v : views)
    assert(v.width == first.width && v.height == first.height && "the views of one run share a size");
  const uint64_t pixels = uint64_t(first.width) * first.height;
  // Each view ping-pongs between its own window of the two scratch buffers.
  const uint64_t scratchPixels = pixels * views.size();
  shared::PostPush push{};
  push.width = first.width;
  push.height = first.height;
  uint64_t source[kMaxPostViews];
  uint32_t sourcePitch[kMaxPostViews];
  for (size_t v = 0; v < views.size(); ++v) {
    source[v] = views[v].words;
    sourcePitch[v] = views[v].pitch;
  }
  int next = 0; // scratch buffer the next filter pass writes
  // One filter pass over every view from its current source into scratch, which becomes its source.
  auto pass = [&](const gpu::ComputeProgram& program) {
    gpu::Buffer& target = scratch(next, scratchPixels);
    for (size_t v = 0; v < views.size(); ++v) {
      push.source = source[v];
      push.sourcePitch = sourcePitch[v];
      push.target = target.address() + v * pixels * 8;
      push.targetPitch = first.width;
      program.dispatch(cmd, tiles(first.width), tiles(first.height), push);
      source[v] = push.target;
      sourcePitch[v] = push.targetPitch;
    }
    gpu::fullBarrier(cmd);
    next ^= 1;
  };
  auto begin = [&](uint32_t span) {
    if (timestamps) timestamps->begin(cmd, firstSpan + span);
  };
  auto end = [&](uint32_t span) {
    if (timestamps) timestamps->end(cmd, firstSpan + span);
  };

  begin(0);
  if (settings.splats()) {
    const bool disc = settings.shape == PointShape::Disc;
    const bool attenuated = settings.sizeMode == PointSizeMode::Attenuated;
    // Attenuated sizes are the same at each view's reference depth (every eye sees the target alike).
    push.pointSize = attenuated ? settings.pointSize * first.referenceDepth : settings.pointSize;
    push.maxPointSize = settings.maxPointSize;
    if (!disc && !attenuated) {
      pass(splat(Splat::SquareRows)); // rows, then columns
      pass(splat(Splat::SquareColumns));
    } else if (attenuated) {
      // Scattered into a cleared buffer: the cost follows the sizes drawn, not the largest allowed.
      gpu::vkCmdFillBuffer(cmd, scratch(next, scratchPixels).handle(), 0, scratchPixels * 8,
                           0xFFFFFFFFu); // kEmptyPixel
      gpu::fullBarrier(cmd);
      pass(splat(disc ? Splat::DiscScatter : Splat::SquareScatter));
    } else {
      push.radius = uint32_t(settings.pointSize / 2); // a disc of diameter s reaches floor(s / 2) pixels
      pass(splat(Splat::DiscWindow));
    }
  }
  end(0);

  begin(1);
  push.radius = settings.dilate;
  if (settings.dilate > 0) pass(dilate_);
  end(1);

  begin(2);
  push.background = first.background;
  push.edlStrength = settings.edlStrength;
  push.edlRadius = settings.edlRadius;
  for (size_t v = 0; v < views.size(); ++v) {
    push.source = source[v];
    push.sourcePitch = sourcePitch[v];
    push.target = views[v].image;
    push.targetPitch = views[v].pitch;
    // The final words go back where the method left its own, unless they are still those.
    push.words = views[v].captureWords && source[v] != views[v].words ? views[v].words : 0;
    compose_.dispatch(cmd, tiles(first.width), tiles(first.height), push);
  }
  gpu::fullBarrier(cmd);
  end(2);
}

PostStats PostStage::stats(const std::vector<double>& spanMs, uint32_t frames) {
  std::vector<double> pass[kPostPasses];
  for (uint32_t f = 0; f < frames; ++f)
    for (uint32_t p = 0; p < kPostPasses; ++p)
      pass[p].push_back(spanMs.at(f * kPostPasses + p));
  return {gpu::median(pass[0]), gpu::median(pass[1]), gpu::median(pass[2])};
}

} // namespace pointrast

#include "render/composite.h"

#include <bit>
#include <cstring>
#include <memory>

#include <glm/glm.hpp>

#include "base/error.h"
#include "base/parallel.h"
#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "gpu/timer.h"
#include "render/method.h"
#include "render/post/post_stage.h"

namespace pointrast {

CompositeResolver::CompositeResolver(gpu::Context& context, uint32_t width, uint32_t height, uint32_t eyes)
    : context_(context), width_(width), height_(height), eyes_(eyes) {}

CompositeResolver::~CompositeResolver() = default;

double int40ScaleOf(std::span<const GpuScene* const> scenes, const Camera& camera) {
  return int40Scale(scenes, camera);
}

std::vector<uint32_t> CompositeResolver::resolve(std::span<const uint64_t> words, const Camera& camera,
                                                 const RenderSettings& settings, double int40Scale,
                                                 std::optional<PostStats>* post,
                                                 std::vector<uint64_t>* ended) {
  const uint64_t pixels = uint64_t(width_) * eyes_ * height_;
  if (words.size() != pixels) throw InputError("composited words do not match the image size");
  const bool int40 = settings.depth == DepthMode::Int40;
  // The colors of the words, as the methods' resolve writes them (shaders/resolve.comp.glsl): int40 words
  // carry RGB24, alpha restored as opaque.
  auto colorOf = [&](uint64_t word) {
    return int40 ? (uint32_t(word) & 0xFFFFFFu) | 0xFF000000u : uint32_t(word);
  };
  // Per-pixel loops on all threads: a 2560x1140 frame is 3 M pixels, resolved every frame a viewer shows.
  auto eachPixel = [&](auto&& body) {
    parallelBlocks(pixels, uint64_t(1) << 16, [&](uint64_t, uint64_t begin, uint64_t end) {
      for (uint64_t i = begin; i < end; ++i)
        body(i);
    });
  };
  std::vector<uint32_t> image(pixels);
  if (!settings.post.enabled()) {
    eachPixel([&](uint64_t i) {
      image[i] = words[i] == shared::kEmptyPixel ? settings.background : colorOf(words[i]);
    });
    if (post) post->reset();
    if (ended) ended->assign(words.begin(), words.end());
    return image;
  }
  validatePostSettings(settings.post);
  if (!post_) post_ = std::make_unique<PostStage>(context_);
  if (!upload_) {
    upload_ = std::make_unique<gpu::Buffer>(context_, pixels * 8, gpu::kBufferUsage, gpu::MemoryKind::Upload,
                                            "composited words");
    words_ = std::make_unique<gpu::Buffer>(context_, pixels * 8, gpu::kBufferUsage, gpu::MemoryKind::Device,
                                           "composited words");
    image_ = std::make_unique<gpu::Buffer>(context_, pixels * 4, gpu::kBufferUsage, gpu::MemoryKind::Device,
                                           "composited image");
    readback_ = std::make_unique<gpu::Buffer>(context_, pixels * 12, gpu::kBufferUsage,
                                              gpu::MemoryKind::Readback, "composited image read back");
  }
  // The stage reads float-depth words: int40 steps are converted as the methods' resolve converts them.
  uint64_t* mapped = static_cast<uint64_t*>(upload_->mapped());
  eachPixel([&](uint64_t i) {
    const uint64_t w = words[i];
    if (!int40 || w == shared::kEmptyPixel) {
      mapped[i] = w;
      return;
    }
    const float depth = float(double(w >> shared::kInt40ColorBits) / int40Scale);
    mapped[i] = uint64_t(std::bit_cast<uint32_t>(depth)) << 32 | colorOf(w);
  });
  const uint32_t pitch = width_ * eyes_;
  std::vector<PostView> views;
  for (uint32_t e = 0; e < eyes_; ++e)
    views.push_back({words_->address() + uint64_t(e) * width_ * 8,
                     image_->address() + uint64_t(e) * width_ * 4, width_, height_, pitch,
                     float(glm::length(camera.target - camera.eye)), settings.background, ended != nullptr});
  gpu::TimestampPool timestamps(context_, kPostPasses);
  context_.submitAndWait([&](VkCommandBuffer cmd) {
    timestamps.reset(cmd);
    VkBufferCopy region{0, 0, pixels * 8};
    gpu::vkCmdCopyBuffer(cmd, upload_->handle(), words_->handle(), 1, &region);
    gpu::fullBarrier(cmd);
    post_->record(cmd, views, settings.post, &timestamps, 0);
    gpu::fullBarrier(cmd);
    // The image, then (for a caller that reads the frame's words) the words the stage ended with.
    VkBufferCopy out[2] = {{0, 0, pixels * 4}, {0, pixels * 4, pixels * 8}};
    gpu::vkCmdCopyBuffer(cmd, image_->handle(), readback_->handle(), 1, &out[0]);
    if (ended) gpu::vkCmdCopyBuffer(cmd, words_->handle(), readback_->handle(), 1, &out[1]);
    gpu::fullBarrier(cmd);
  });
  if (post) *post = PostStage::stats(timestamps.milliseconds(), 1);
  readback_->invalidate();
  const auto* from = static_cast<const uint8_t*>(readback_->mapped());
  if (ended) ended->resize(pixels);
  parallelBlocks(pixels, uint64_t(1) << 16, [&](uint64_t, uint64_t begin, uint64_t end) {
    std::memcpy(image.data() + begin, from + begin * 4, (end - begin) * 4);
    if (ended) std::memcpy(ended->data() + begin, from + pixels * 4 + begin * 8, (end - begin) * 8);
  });
  return image;
}

} // namespace pointrast

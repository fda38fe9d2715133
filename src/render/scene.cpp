#include "render/scene.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "base/error.h"
#include "base/progress.h"
#include "gpu/context.h"

namespace pointrast {

namespace {

constexpr uint64_t kStagingBytes = 64ull << 20; // per copy: 64 MiB, 4 M points of 16 B
constexpr uint64_t kStagingPoints = kStagingBytes / 16;
constexpr uint64_t kPartAlign = 10240;           // parts hold whole 2022-style batches
constexpr uint64_t kMaxPartPoints = 64ull << 20; // 64 M points: 768 MiB of positions

} // namespace

GpuScene::GpuScene(gpu::Context& context, const PointCloud& cloud, const UploadOptions& options)
    : origin_(cloud.origin()), bounds_(cloud.bounds) {
  uint64_t first = std::min(options.first, cloud.size());
  uint64_t count = std::min(options.count, cloud.size() - first);
  pointCount_ = count;
  uint64_t limit = std::min(context.maxAllocationSize(), context.maxBufferSize());
  uint64_t partPoints = options.maxPartPoints;
  if (partPoints == 0) partPoints = std::min(kMaxPartPoints, (limit / 12) / kPartAlign * kPartAlign);
  if (partPoints == 0)
    throw UnsupportedError("device buffers are too small to hold even one batch of points");

  uint64_t needed = count * 16;
  if (needed > context.deviceLocalBytes())
    throw UnsupportedError("the cloud needs " + std::to_string(needed >> 20) +
                           " MiB of GPU memory but device '" + context.info().name + "' has " +
                           std::to_string(context.deviceLocalBytes() >> 20) + " MiB");

  for (uint64_t at = 0; at < count; at += partPoints) {
    ScenePart part;
    part.first = first + at;
    part.count = std::min(partPoints, count - at);
    std::string index = std::to_string(parts_.size());
    part.positions = gpu::Buffer(context, part.count * 12, gpu::kBufferUsage, gpu::MemoryKind::Device,
                                 "positions " + index);
    part.colors =
        gpu::Buffer(context, part.count * 4, gpu::kBufferUsage, gpu::MemoryKind::Device, "colors " + index);
    parts_.push_back(std::move(part));
  }
  if (count == 0) return;

  gpu::Buffer staging(context, kStagingBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryKind::Upload,
                      "upload staging");
  auto* stagingFloats = static_cast<float*>(staging.mapped());
  auto* stagingColors =
      reinterpret_cast<uint32_t*>(static_cast<char*>(staging.mapped()) + kStagingPoints * 12);
  Progress progress("uploading to GPU", count, " points", options.progress);
  for (const ScenePart& part : parts_) {
    for (uint64_t at = 0; at < part.count; at += kStagingPoints) {
      uint64_t n = std::min(kStagingPoints, part.count - at);
      toRelativeFloat(stagingFloats, cloud, part.first + at, n, origin_);
      displayColors(stagingColors, cloud, part.first + at, n);
      context.submitAndWait([&](VkCommandBuffer cmd) {
        VkBufferCopy pos{0, at * 12, n * 12};
        VkBufferCopy col{kStagingPoints * 12, at * 4, n * 4};
        gpu::vkCmdCopyBuffer(cmd, staging.handle(), part.positions.handle(), 1, &pos);
        gpu::vkCmdCopyBuffer(cmd, staging.handle(), part.colors.handle(), 1, &col);
      });
      progress.advance(n);
    }
  }
}

} // namespace pointrast

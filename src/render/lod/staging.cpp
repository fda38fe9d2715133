#include "render/lod/staging.h"

#include <cassert>

#include "gpu/shared_types.h"

namespace pointrast::lod {

StagingBlocks::StagingBlocks(gpu::Context& context, uint32_t blocks)
    : buffer_(context, uint64_t(blocks) * shared::kLodPageBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
              gpu::MemoryKind::Upload, "LOD node staging"),
      capacity_(blocks) {
  assert(blocks > 0);
  free_.reserve(blocks);
  for (uint32_t b = blocks; b-- > 0;)
    free_.push_back(b);
}

std::optional<std::vector<uint32_t>> StagingBlocks::take(uint32_t count) {
  assert(count <= capacity_);
  std::unique_lock lock(mutex_);
  freed_.wait(lock, [&] { return stopped_ || free_.size() >= count; });
  if (stopped_) return std::nullopt;
  std::vector<uint32_t> taken(free_.end() - count, free_.end());
  free_.resize(free_.size() - count);
  return taken;
}

void StagingBlocks::give(const std::vector<uint32_t>& blocks) {
  if (blocks.empty()) return;
  {
    std::lock_guard lock(mutex_);
    free_.insert(free_.end(), blocks.begin(), blocks.end());
  }
  freed_.notify_all();
}

void StagingBlocks::stop() {
  {
    std::lock_guard lock(mutex_);
    stopped_ = true;
  }
  freed_.notify_all();
}

uint8_t* StagingBlocks::block(uint32_t b) const {
  return static_cast<uint8_t*>(buffer_.mapped()) + offset(b);
}

uint64_t StagingBlocks::offset(uint32_t b) const {
  return uint64_t(b) * shared::kLodPageBytes;
}

} // namespace pointrast::lod

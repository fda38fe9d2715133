// Host-visible memory between the node readers and the GPU node cache: blocks of one page each
// (kLodPageBytes), into which readers encode nodes directly and from which a frame's commands copy them into
// the cache. Its size bounds the host memory of nodes read but not yet uploaded; a reader waits for free
// blocks instead of allocating more.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "gpu/buffer.h"

namespace pointrast::lod {

class StagingBlocks {
public:
  StagingBlocks(gpu::Context& context, uint32_t blocks);

  uint32_t capacity() const { return capacity_; }
  // Takes `count` (<= capacity) blocks, waiting while fewer are free; nullopt once stop() was called.
  std::optional<std::vector<uint32_t>> take(uint32_t count);
  void give(const std::vector<uint32_t>& blocks);
  // Wakes and refuses every waiting and later take(): the readers are shutting down.
  void stop();

  uint8_t* block(uint32_t b) const;
  uint64_t offset(uint32_t b) const;
  VkBuffer handle() const { return buffer_.handle(); }

private:
  gpu::Buffer buffer_;
  uint32_t capacity_;
  std::mutex mutex_;
  std::condition_variable freed_;
  std::vector<uint32_t> free_;
  bool stopped_ = false;
};

} // namespace pointrast::lod

// GPU memory of the node cache: pages of kLodPageBytes (shared.h) in buffers of up to 256 MiB ("slabs"),
// created as pages are first needed, up to a byte budget. Pages are allocated one by one, so a node's pages
// need not be neighbours, nothing fragments, and a node of any size fits wherever as many pages are free.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gpu/buffer.h"

namespace pointrast::lod {

class PagePool {
public:
  // Throws UnsupportedError when the budget holds no page.
  PagePool(gpu::Context& context, uint64_t budgetBytes);

  uint64_t capacity() const { return capacity_; } // pages the budget holds
  uint64_t used() const { return used_; }
  uint64_t free() const { return capacity_ - used_; }
  // Appends `count` pages to out, creating slabs as needed; false (out unchanged) if fewer are free.
  // Throws UnsupportedError when the device refuses a slab within the budget.
  bool allocate(uint64_t count, std::vector<uint32_t>& out);
  void release(std::span<const uint32_t> pages);

  uint64_t address(uint32_t page) const;
  VkBuffer buffer(uint32_t page) const;
  uint64_t offset(uint32_t page) const; // in buffer(page)

private:
  gpu::Context& context_;
  uint64_t capacity_ = 0;
  uint64_t used_ = 0;
  uint32_t slabPages_ = 0;
  std::vector<gpu::Buffer> slabs_;
  std::vector<uint32_t> free_; // released pages of existing slabs
  uint64_t fresh_ = 0;         // pages handed out from slabs at least once (the rest were never used)
};

} // namespace pointrast::lod

#include "render/lod/page_pool.h"

#include <algorithm>
#include <string>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"

namespace pointrast::lod {

namespace {

// 256 MiB a slab (4096 pages): few allocations for a budget of tens of GiB, and a slab is far below the
// largest buffer of any device.
constexpr uint64_t kSlabBytes = uint64_t(256) << 20;

} // namespace

PagePool::PagePool(gpu::Context& context, uint64_t budgetBytes) : context_(context) {
  capacity_ = budgetBytes / shared::kLodPageBytes;
  if (capacity_ == 0)
    throw UnsupportedError("a GPU memory budget of " + std::to_string(budgetBytes) +
                           " bytes holds no page of the node cache (" +
                           std::to_string(shared::kLodPageBytes) + " bytes)");
  const uint64_t limit = std::min({kSlabBytes, context.maxBufferSize(), context.maxAllocationSize()});
  slabPages_ = uint32_t(std::max<uint64_t>(1, limit / shared::kLodPageBytes));
}

bool PagePool::allocate(uint64_t count, std::vector<uint32_t>& out) {
  if (count > free()) return false;
  const size_t start = out.size();
  for (uint64_t k = 0; k < count; ++k) {
    if (!free_.empty()) {
      out.push_back(free_.back());
      free_.pop_back();
      continue;
    }
    const uint64_t slab = fresh_ / slabPages_;
    if (slab == slabs_.size()) {
      const uint64_t pages = std::min<uint64_t>(slabPages_, capacity_ - fresh_);
      try {
        slabs_.emplace_back(context_, pages * shared::kLodPageBytes, gpu::kBufferUsage,
                            gpu::MemoryKind::Device, "LOD node cache " + std::to_string(slab));
      } catch (...) {
        free_.insert(free_.end(), out.begin() + long(start), out.end()); // not counted in used_ yet
        out.resize(start);
        throw;
      }
    }
    out.push_back(uint32_t(fresh_++));
  }
  used_ += count;
  return true;
}

void PagePool::release(std::span<const uint32_t> pages) {
  free_.insert(free_.end(), pages.begin(), pages.end());
  used_ -= pages.size();
}

uint64_t PagePool::address(uint32_t page) const {
  return slabs_[page / slabPages_].address() + offset(page);
}

VkBuffer PagePool::buffer(uint32_t page) const {
  return slabs_[page / slabPages_].handle();
}

uint64_t PagePool::offset(uint32_t page) const {
  return uint64_t(page % slabPages_) * shared::kLodPageBytes;
}

} // namespace pointrast::lod

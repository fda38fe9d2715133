#include "gpu/bandwidth.h"

#include <algorithm>
#include <cassert>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/timer.h"

namespace pointrast::gpu {

namespace {
// Untimed copies first: they fault in the pages (software devices), raise clocks and fill caches.
constexpr int kWarmup = 2;
constexpr uint64_t kMinBytes = 4096;
} // namespace

uint64_t copyBytesFor(const Context& context, uint64_t requested) {
  uint64_t limit =
      std::min({context.deviceLocalBytes() / 4, context.maxBufferSize(), context.maxAllocationSize()});
  uint64_t bytes = std::min(requested, limit) / 256 * 256;
  return std::max(bytes, kMinBytes);
}

CopyBandwidth measureCopy(Context& context, uint64_t bytes, int repeats) {
  assert(repeats >= 1);
  CopyBandwidth result;
  result.bytes = copyBytesFor(context, bytes);
  result.repeats = repeats;
  constexpr VkBufferUsageFlags usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  Buffer source(context, result.bytes, usage, MemoryKind::Device, "copy bandwidth source");
  Buffer destination(context, result.bytes, usage, MemoryKind::Device, "copy bandwidth destination");
  TimestampPool timestamps(context, uint32_t(repeats));
  VkBufferCopy region{0, 0, result.bytes};
  context.submitAndWait([&](VkCommandBuffer cmd) {
    timestamps.reset(cmd);
    // Defined contents, so no driver can take a shortcut for never-written memory.
    vkCmdFillBuffer(cmd, source.handle(), 0, VK_WHOLE_SIZE, 0x5A5A5A5Au);
    fullBarrier(cmd);
    for (int w = 0; w < kWarmup; ++w) {
      vkCmdCopyBuffer(cmd, source.handle(), destination.handle(), 1, &region);
      fullBarrier(cmd);
    }
    for (int r = 0; r < repeats; ++r) {
      timestamps.begin(cmd, uint32_t(r));
      vkCmdCopyBuffer(cmd, source.handle(), destination.handle(), 1, &region);
      timestamps.end(cmd, uint32_t(r));
      fullBarrier(cmd);
    }
  });
  result.medianMs = median(timestamps.milliseconds());
  result.bytesPerSecond = result.medianMs > 0 ? 2.0 * double(result.bytes) / (result.medianMs * 1e-3) : 0.0;
  return result;
}

double measureCopyBandwidth(Context& context, uint64_t bytes, int repeats) {
  return measureCopy(context, bytes, repeats).bytesPerSecond;
}

} // namespace pointrast::gpu

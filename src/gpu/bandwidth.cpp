#include "gpu/bandwidth.h"

#include <algorithm>
#include <cassert>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/program.h"
#include "gpu/shared_types.h"
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
  // A multiple of 4 KiB, and at most 2^32 - 1 16-byte vectors for the shader copy.
  uint64_t bytes = std::min({requested, limit, uint64_t(0xFFFFFFFFu) * 16}) / 4096 * 4096;
  return std::max(bytes, kMinBytes);
}

CopyBandwidth measureCopy(Context& context, uint64_t bytes, int repeats) {
  assert(repeats >= 1);
  CopyBandwidth result;
  result.bytes = copyBytesFor(context, bytes);
  result.repeats = repeats;
  Buffer source(context, result.bytes, kBufferUsage, MemoryKind::Device, "copy bandwidth source");
  Buffer destination(context, result.bytes, kBufferUsage, MemoryKind::Device, "copy bandwidth destination");
  ComputeProgram shaderCopy(context, "copy.comp");
  shared::CopyPush push{};
  push.source = source.address();
  push.destination = destination.address();
  push.count = uint32_t(result.bytes / 16);
  Grid grid = gridFor(push.count, shaderCopy.groupSize());
  push.groupsX = grid.x;
  TimestampPool timestamps(context, uint32_t(2 * repeats));
  VkBufferCopy region{0, 0, result.bytes};
  context.submitAndWait([&](VkCommandBuffer cmd) {
    timestamps.reset(cmd);
    // Defined contents, so no driver can take a shortcut for never-written memory.
    vkCmdFillBuffer(cmd, source.handle(), 0, VK_WHOLE_SIZE, 0x5A5A5A5Au);
    fullBarrier(cmd);
    for (int w = 0; w < kWarmup; ++w) {
      vkCmdCopyBuffer(cmd, source.handle(), destination.handle(), 1, &region);
      fullBarrier(cmd);
      shaderCopy.dispatch(cmd, grid.x, grid.y, push);
      fullBarrier(cmd);
    }
    for (int r = 0; r < repeats; ++r) {
      timestamps.begin(cmd, uint32_t(r));
      vkCmdCopyBuffer(cmd, source.handle(), destination.handle(), 1, &region);
      timestamps.end(cmd, uint32_t(r));
      fullBarrier(cmd);
      timestamps.begin(cmd, uint32_t(repeats + r));
      shaderCopy.dispatch(cmd, grid.x, grid.y, push);
      timestamps.end(cmd, uint32_t(repeats + r));
      fullBarrier(cmd);
    }
  });
  std::vector<double> ms = timestamps.milliseconds();
  double transferMs = median(std::vector<double>(ms.begin(), ms.begin() + repeats));
  double shaderMs = median(std::vector<double>(ms.begin() + repeats, ms.end()));
  auto rate = [&](double milliseconds) {
    return milliseconds > 0 ? 2.0 * double(result.bytes) / (milliseconds * 1e-3) : 0.0;
  };
  result.transferBytesPerSecond = rate(transferMs);
  result.shaderBytesPerSecond = rate(shaderMs);
  result.medianMs = std::min(transferMs, shaderMs);
  result.bytesPerSecond = std::max(result.transferBytesPerSecond, result.shaderBytesPerSecond);
  return result;
}

} // namespace pointrast::gpu

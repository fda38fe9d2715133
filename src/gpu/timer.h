// GPU time from timestamp queries (never the wall clock): a pool of pairs, one pair per timed span.
#pragma once

#include <cstdint>
#include <vector>

#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

class Context;

class TimestampPool {
public:
  TimestampPool(Context& context, uint32_t spans);
  ~TimestampPool();
  TimestampPool(const TimestampPool&) = delete;
  TimestampPool& operator=(const TimestampPool&) = delete;

  void reset(VkCommandBuffer cmd);
  void begin(VkCommandBuffer cmd, uint32_t span);
  void end(VkCommandBuffer cmd, uint32_t span);
  // Milliseconds of each span, after the command buffer completed.
  std::vector<double> milliseconds();

private:
  Context& context_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t spans_;
};

double median(std::vector<double> values);

} // namespace pointrast::gpu

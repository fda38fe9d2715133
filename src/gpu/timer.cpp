#include "gpu/timer.h"

#include <algorithm>

#include "gpu/context.h"

namespace pointrast::gpu {

TimestampPool::TimestampPool(Context& context, uint32_t spans) : context_(context), spans_(spans) {
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = 2 * spans;
  VK_CHECK(vkCreateQueryPool(context.device(), &info, nullptr, &pool_));
  context.setName(VK_OBJECT_TYPE_QUERY_POOL, uint64_t(pool_), "frame timestamps");
}

TimestampPool::~TimestampPool() {
  if (deviceFaulted()) return; // the GPU may still use it: leave it to process exit
  vkDestroyQueryPool(context_.device(), pool_, nullptr);
}

void TimestampPool::reset(VkCommandBuffer cmd) {
  vkCmdResetQueryPool(cmd, pool_, 0, 2 * spans_);
}

void TimestampPool::begin(VkCommandBuffer cmd, uint32_t span) {
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_, 2 * span);
}

void TimestampPool::end(VkCommandBuffer cmd, uint32_t span) {
  vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_, 2 * span + 1);
}

std::vector<double> TimestampPool::milliseconds() {
  std::vector<uint64_t> ticks(2 * spans_);
  VK_CHECK(vkGetQueryPoolResults(context_.device(), pool_, 0, 2 * spans_, ticks.size() * sizeof(uint64_t),
                                 ticks.data(), sizeof(uint64_t),
                                 VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  std::vector<double> ms(spans_);
  for (uint32_t s = 0; s < spans_; ++s)
    ms[s] = double(ticks[2 * s + 1] - ticks[2 * s]) * context_.timestampPeriodNs() * 1e-6;
  return ms;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

} // namespace pointrast::gpu

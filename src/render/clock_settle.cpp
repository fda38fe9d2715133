#include "render/clock_settle.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace pointrast {

double settleClocks(const std::function<double(uint32_t frames)>& renderMs,
                    const std::function<double()>& clock) {
  const auto steadyStart = std::chrono::steady_clock::now();
  const std::function<double()> now = clock ? clock : [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - steadyStart).count();
  };
  const double start = now();
  auto elapsed = [&] { return now() - start; };
  // Round 0 is one frame that only sizes the rounds; the rounds after it are compared with the fastest of
  // them so far. Two rounds that agree with each other but not with a faster earlier one are clocks that fell
  // again, not the device's speed.
  uint32_t frames = 1;
  double best = 0, previous = 0;
  for (int round = 0; round < kSettleMaxRounds && elapsed() < kSettleMaxSeconds; ++round) {
    const double ms = renderMs(frames);
    if (!(ms > 0)) break; // nothing measurable to settle on
    if (round >= 1) best = round == 1 ? ms : std::min(best, ms);
    const double near = best * (1 + kSettleTolerance);
    if (round >= 2 && previous <= near && ms <= near && elapsed() >= kSettleMinSeconds) break;
    previous = ms;
    frames = uint32_t(std::clamp(std::ceil(kSettleRoundMs / ms), 1.0, 200.0));
  }
  return elapsed();
}

bool settlesClocks(const gpu::Context& context) {
  // An injected device fault is placed by counting submissions; settling takes a number of them that
  // depends on the device's clocks, so it is left out of such runs.
  return !context.info().software() && !gpu::deviceLossInjected();
}

} // namespace pointrast

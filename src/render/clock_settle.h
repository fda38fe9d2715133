// GPU clocks settled before a timing, so that the first figures a user sees (`pointrast render`) are
// measured like the benchmark's. GPU clocks fall to idle while the host prepares a scene for seconds (an
// H200 idles at 345 MHz and boosts to 1980), and they may stay there through a whole submission: on the
// H200, a method timed first after such a pause ran 5.7x slow in all 17 frames of its one submission. So
// before the timed frames, renderMs(frames) (which renders that many frames in one submission and returns
// their median ms) is called in rounds of about 30 ms of GPU work until the last two rounds are both within 3
// % of the fastest round so far, after at least 0.2 s; or until 3 s or 100 rounds have passed. Two equally
// slow rounds after a faster one do not settle it.
#pragma once

#include <cstdint>
#include <functional>

#include "gpu/context.h"

namespace pointrast {

constexpr double kSettleRoundMs = 30;
constexpr double kSettleTolerance = 0.03;
constexpr double kSettleMinSeconds = 0.2;
constexpr double kSettleMaxSeconds = 3;
constexpr int kSettleMaxRounds = 100; // also where rounds are short (200 frames of under 0.15 ms)

// Returns the wall seconds it took. `clock` (seconds, monotonic) is the steady clock unless a test passes
// its own, so that its rounds do not depend on the machine's load.
double settleClocks(const std::function<double(uint32_t frames)>& renderMs,
                    const std::function<double()>& clock = {});

// Whether settling is worth its time on this device: GPUs change their clocks, a software device does not.
// Runs with an injected device fault (counted in submissions) are left unsettled too.
bool settlesClocks(const gpu::Context& context);

// Settles the clocks where settlesClocks(context) with render(settings) as the rounds, each with
// `frames` timed frames and no warm-up. `render` returns the renderer's stats (medianMs). Returns whether
// the clocks were settled.
template <class Settings, class Render>
bool settleClocksWith(const gpu::Context& context, const Settings& settings, Render&& render) {
  if (!settlesClocks(context)) return false;
  settleClocks([&](uint32_t frames) {
    Settings round = settings;
    round.frames = frames;
    round.warmup = 0;
    return double(render(round).medianMs);
  });
  return true;
}

// A clock that rose during the timed frames shows as a median far above the fastest frame (on an H200 after
// a long host pause: 8.96 ms median, 1.66 ms fastest, the idle/boost clock ratio). Where settlesClocks
// holds, the timed frames are rendered again, up to kRetimeAttempts times, until the median is within
// kRetimeSpread of the fastest frame; `settled` says whether it ended so. A software device is always
// settled.
constexpr int kRetimeAttempts = 5;
constexpr double kRetimeSpread = 1.25;
template <class Settings, class Render>
auto timeSettled(const gpu::Context& context, const Settings& settings, Render&& render, bool& settled) {
  auto stats = render(settings);
  settled = true;
  if (!settlesClocks(context)) return stats;
  for (int i = 0; i < kRetimeAttempts && stats.medianMs > kRetimeSpread * stats.minMs; ++i)
    stats = render(settings);
  settled = !(stats.medianMs > kRetimeSpread * stats.minMs);
  return stats;
}

} // namespace pointrast

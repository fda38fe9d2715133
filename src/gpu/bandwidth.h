// The device's buffer-copy bandwidth, measured in the same run as a benchmark so that every method's
// effective bandwidth can be stated as a fraction of what the memory system delivers (docs/design.md,
// "Measuring performance"). Two copies between two device-local buffers, each timed with timestamp
// queries after a warm-up, median over the repeats: vkCmdCopyBuffer, and a compute shader moving 16 bytes
// per invocation. The faster is the device's copy bandwidth (on NVIDIA vkCmdCopyBuffer uses a copy
// engine well below the memory's rate, which would flatter every method measured against it).
#pragma once

#include <cstdint>

namespace pointrast::gpu {

class Context;

struct CopyBandwidth {
  uint64_t bytes = 0;                // size of one copy (after clamping)
  int repeats = 0;                   // timed copies
  double medianMs = 0;               // GPU time of one copy by the faster way, median over the repeats
  double bytesPerSecond = 0;         // 2 * bytes / median: read + written (see below), the faster way
  double transferBytesPerSecond = 0; // vkCmdCopyBuffer alone
  double shaderBytesPerSecond = 0;   // the compute-shader copy alone
};

// What measureCopy() copies when asked for `requested` bytes: at most a quarter of device-local memory
// (two buffers of it must fit beside whatever else is resident), the largest buffer and allocation,
// rounded down to 256 B; at least 4 KiB.
uint64_t copyBytesFor(const Context& context, uint64_t requested);

// A copy moves every byte twice through DRAM (one read, one write), so the figure returned counts
// bytes read + bytes written per second: it is what a method that only reads its point data could at
// most stream, and the denominator of "effective bandwidth as a fraction of copy bandwidth".
// Throws UnsupportedError when the buffers cannot be allocated.
CopyBandwidth measureCopy(Context& context, uint64_t bytes = uint64_t(1) << 30, int repeats = 10);

} // namespace pointrast::gpu

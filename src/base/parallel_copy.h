// memcpy on all hardware threads, for copies into and out of mapped GPU staging memory: one core's copy
// bandwidth is far below the bus's.
#pragma once

#include <cstdint>
#include <cstring>

#include "base/parallel.h"

namespace pointrast {

inline void copyOnAllThreads(void* to, const void* from, uint64_t size) {
  parallelBlocks(size, uint64_t(1) << 21, [&](uint64_t, uint64_t begin, uint64_t end) {
    std::memcpy(static_cast<uint8_t*>(to) + begin, static_cast<const uint8_t*>(from) + begin, end - begin);
  });
}

} // namespace pointrast

// Deterministic parallel loops over index ranges. Work is cut into fixed-size blocks whose boundaries
// do not depend on the number of threads, so a body that seeds its random numbers from the block index
// gives the same result on 2 cores and on 128.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace pointrast {

// Processes that share this machine's cores (the ranks of a distributed job on one host, src/mpi): each
// counts hardwareThreads() as its part of them. 1 outside a job.
inline std::atomic<unsigned>& threadShares() {
  static std::atomic<unsigned> shares{1};
  return shares;
}
inline void setThreadShares(unsigned processes) {
  threadShares() = processes ? processes : 1;
}

// The threads this process uses: the hardware's, or its part of them when processes share the machine.
inline unsigned hardwareThreads() {
  unsigned n = std::thread::hardware_concurrency();
  n = n ? n : 1;
  return std::max(1u, n / threadShares().load());
}

// Calls body(blockIndex, begin, end) for consecutive blocks [begin, end) of at most blockSize indices
// covering [0, count), on at most maxThreads threads (0: all hardware threads). The first exception
// thrown by a body is rethrown.
template <class Body>
void parallelBlocksOn(unsigned maxThreads, uint64_t count, uint64_t blockSize, Body&& body) {
  if (count == 0) return;
  uint64_t blocks = (count + blockSize - 1) / blockSize;
  unsigned threads =
      static_cast<unsigned>(std::min<uint64_t>(maxThreads ? maxThreads : hardwareThreads(), blocks));
  std::atomic<uint64_t> next{0};
  std::exception_ptr error;
  std::mutex errorMutex;
  auto worker = [&] {
    for (;;) {
      uint64_t b = next.fetch_add(1);
      if (b >= blocks) return;
      try {
        uint64_t begin = b * blockSize;
        body(b, begin, std::min(count, begin + blockSize));
      } catch (...) {
        std::lock_guard lock(errorMutex);
        if (!error) error = std::current_exception();
        next = blocks;
        return;
      }
    }
  };
  if (threads <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(threads - 1);
    for (unsigned t = 1; t < threads; ++t)
      pool.emplace_back(worker);
    worker();
    for (auto& t : pool)
      t.join();
  }
  if (error) std::rethrow_exception(error);
}

// The same on all hardware threads.
template <class Body> void parallelBlocks(uint64_t count, uint64_t blockSize, Body&& body) {
  parallelBlocksOn(0, count, blockSize, body);
}

} // namespace pointrast

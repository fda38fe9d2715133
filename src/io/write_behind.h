// Write-behind for a large file written once, front to back (an octree's octree.bin): the kernel is
// asked to start writing each completed window of `window` bytes as soon as it is complete
// (sync_file_range SYNC_FILE_RANGE_WRITE), the window before it is waited for and dropped from the page
// cache (posix_fadvise DONTNEED). Dirty pages stay near two windows whatever the file's size, so the
// writers never hit the kernel's dirty limit, where every process writing to the disk is throttled, and
// the written file does not push the build's input out of the page cache.
//
// Writers report ranges as their pwrite returns, from any thread and in any order; a window is
// complete once every byte before its end was reported. The flushing runs on a thread of its own, so a
// writer never waits for the disk. Only hints: the file's bytes are those written, and on file systems
// without page-cache writeback (tmpfs) the calls do nothing.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <thread>

namespace pointrast::io::detail {

class WriteBehind {
public:
  static constexpr uint64_t kDefaultWindow = uint64_t(64) << 20;

  // fd: open for writing, written from offset 0 on without holes; window >= 1 MiB.
  explicit WriteBehind(int fd, uint64_t window = kDefaultWindow);
  ~WriteBehind(); // stops the flushing thread; the file stays as written
  WriteBehind(const WriteBehind&) = delete;
  WriteBehind& operator=(const WriteBehind&) = delete;

  // [offset, offset + n) holds its final bytes. Thread-safe.
  void written(uint64_t offset, uint64_t n);
  // Flushes what is complete, stops the thread and returns the first I/O error writeback reported
  // (errno value; 0 if none). Call once, before closing the file.
  int finish();

  // Bytes handed to writeback so far, and the flushing thread's time waiting for the disk.
  uint64_t flushedBytes() const;
  double waitSeconds() const;

private:
  void run();

  const int fd_;
  const uint64_t window_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::map<uint64_t, uint64_t> ahead_; // completed ranges past the frontier: offset -> end
  uint64_t frontier_ = 0;              // every byte before it is written
  uint64_t started_ = 0;               // writeback started for [0, started_)
  uint64_t dropped_ = 0;               // waited for and dropped from the cache: [0, dropped_)
  double waitSeconds_ = 0;
  int error_ = 0;
  bool stop_ = false;
  std::thread thread_;
};

} // namespace pointrast::io::detail

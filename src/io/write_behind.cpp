#include "io/write_behind.h"

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <chrono>

#include <fcntl.h>

namespace pointrast::io::detail {

namespace {

// File systems without writeback of their own (tmpfs, some overlays, FUSE) refuse or ignore the hints;
// the data is written either way.
bool isRealError(int error) {
  return error != 0 && error != EINVAL && error != ESPIPE && error != ENOSYS && error != EOPNOTSUPP;
}

} // namespace

WriteBehind::WriteBehind(int fd, uint64_t window) : fd_(fd), window_(std::max<uint64_t>(window, 1u << 20)) {
  assert(fd >= 0);
  thread_ = std::thread([this] { run(); });
}

WriteBehind::~WriteBehind() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void WriteBehind::written(uint64_t offset, uint64_t n) {
  if (n == 0) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (offset > frontier_) {
    ahead_.emplace(offset, offset + n);
    return;
  }
  frontier_ = std::max(frontier_, offset + n);
  for (auto it = ahead_.begin(); it != ahead_.end() && it->first <= frontier_; it = ahead_.erase(it))
    frontier_ = std::max(frontier_, it->second);
  if (frontier_ - started_ >= window_) wake_.notify_one();
}

int WriteBehind::finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

uint64_t WriteBehind::flushedBytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return started_;
}

double WriteBehind::waitSeconds() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return waitSeconds_;
}

void WriteBehind::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stop_ || frontier_ - started_ >= window_; });
    const bool stopping = stop_;
    // Whole windows while writing; at the end whatever is complete.
    const uint64_t begin = started_;
    const uint64_t end = stopping ? frontier_ : begin + (frontier_ - begin) / window_ * window_;
    const uint64_t dropBegin = dropped_;
    if (end == begin) break; // stopping with nothing left
    lock.unlock();

    int error = 0;
    if (::sync_file_range(fd_, off_t(begin), off_t(end - begin), SYNC_FILE_RANGE_WRITE) != 0) error = errno;
    // The windows before this one were started one round earlier: wait for them, then drop them.
    double waited = 0;
    if (begin > dropBegin) {
      const auto t0 = std::chrono::steady_clock::now();
      if (::sync_file_range(fd_, off_t(dropBegin), off_t(begin - dropBegin),
                            SYNC_FILE_RANGE_WAIT_BEFORE | SYNC_FILE_RANGE_WRITE |
                                SYNC_FILE_RANGE_WAIT_AFTER) != 0 &&
          !isRealError(error))
        error = errno;
      waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ::posix_fadvise(fd_, off_t(dropBegin), off_t(begin - dropBegin), POSIX_FADV_DONTNEED);
    }

    lock.lock();
    started_ = end;
    dropped_ = begin;
    waitSeconds_ += waited;
    if (isRealError(error) && error_ == 0) error_ = error;
    if (stopping) break;
  }
}

} // namespace pointrast::io::detail

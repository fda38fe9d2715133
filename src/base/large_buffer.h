// A large array of trivially copyable elements, left uninitialized (a std::vector zeroes every element
// first, one more pass over gigabytes), mapped on its own so that it goes back to the system when freed.
// For the octree builder's point arrays; small arrays stay in std::vector. Transparent huge pages
// (madvise MADV_HUGEPAGE) were tried: on the shared 2-core test machine the kernel's compaction on page
// faults cost more system time than the fewer faults saved (distribute phase 3x slower), so the pages
// stay as the system's default decides.
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>

#include <sys/mman.h>

namespace pointrast {

template <class T> class LargeBuffer {
  static_assert(std::is_trivially_copyable_v<T>);

public:
  LargeBuffer() = default;
  // Throws std::bad_alloc when the memory cannot be mapped (the kernel's overcommit check refuses it up
  // front, rather than a page fault failing later).
  explicit LargeBuffer(size_t count) : count_(count) {
    if (count == 0) return;
    void* p = ::mmap(nullptr, bytes(), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    data_ = static_cast<T*>(p);
  }
  ~LargeBuffer() { release(); }
  LargeBuffer(LargeBuffer&& o) noexcept : data_(o.data_), count_(o.count_) {
    o.data_ = nullptr;
    o.count_ = 0;
  }
  LargeBuffer& operator=(LargeBuffer&& o) noexcept {
    if (this != &o) {
      release();
      data_ = o.data_;
      count_ = o.count_;
      o.data_ = nullptr;
      o.count_ = 0;
    }
    return *this;
  }
  LargeBuffer(const LargeBuffer&) = delete;
  LargeBuffer& operator=(const LargeBuffer&) = delete;

  T* data() { return data_; }
  const T* data() const { return data_; }
  size_t size() const { return count_; }
  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }

private:
  size_t bytes() const { return count_ * sizeof(T); }
  void release() {
    if (data_) ::munmap(data_, bytes());
    data_ = nullptr;
    count_ = 0;
  }
  T* data_ = nullptr;
  size_t count_ = 0;
};

} // namespace pointrast

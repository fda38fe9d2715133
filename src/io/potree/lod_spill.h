// Temporary chunk files of an out-of-core octree build (private to src/io): the "distribute" phase
// appends each point to its chunk's file, the "index" phase reads a chunk back whole and deletes the file.
// Threads buffer points per chunk and append whole buffers (O_APPEND makes each write land at the end
// whatever other threads do); the order of points inside a file does not matter, indexing sorts it.
// A point is its record (24 bytes) or, where points carry tails, its record, its place in the input
// (uint64) and its tail.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <vector>

#include "cloud/point_record.h"

namespace pointrast::io::detail {

class ChunkSpill {
public:
  // Creates dir (which must not exist yet) for `chunks` chunk files; tailBytes: each point's tail (0: the
  // points carry none).
  ChunkSpill(std::filesystem::path dir, size_t chunks, uint32_t tailBytes = 0);
  // Removes dir with whatever is left in it.
  ~ChunkSpill();
  ChunkSpill(const ChunkSpill&) = delete;
  ChunkSpill& operator=(const ChunkSpill&) = delete;

  // One thread's buffers: appended to the files when they hold bufferBytes, and at flush().
  class Writer {
  public:
    Writer(ChunkSpill& spill, uint64_t bufferBytes);
    void add(uint32_t chunk, const PointRecord& record) {
      std::vector<uint8_t>& b = buffers_[chunk];
      if (b.empty()) used_.push_back(chunk);
      const size_t at = b.size();
      b.resize(at + sizeof record);
      std::memcpy(b.data() + at, &record, sizeof record);
      if (++buffered_ >= limit_) flush();
    }
    // A point with its place in the input and its tail (spill.tailBytes() bytes).
    void add(uint32_t chunk, const PointRecord& record, uint64_t place, const uint8_t* tail) {
      std::vector<uint8_t>& b = buffers_[chunk];
      if (b.empty()) used_.push_back(chunk);
      const size_t at = b.size();
      b.resize(at + spill_.rowBytes_);
      std::memcpy(b.data() + at, &record, sizeof record);
      std::memcpy(b.data() + at + sizeof record, &place, sizeof place);
      std::memcpy(b.data() + at + sizeof record + sizeof place, tail, spill_.tailBytes_);
      if (++buffered_ >= limit_) flush();
    }
    void flush();

  private:
    ChunkSpill& spill_;
    std::vector<std::vector<uint8_t>> buffers_;
    std::vector<uint32_t> used_;
    uint64_t buffered_ = 0, limit_ = 0;
  };

  // Reads chunk i's file (which must hold exactly `points` points) into out (rowBytes() each) and
  // deletes it.
  void read(size_t chunk, uint64_t points, std::vector<uint8_t>& out);
  uint32_t tailBytes() const { return tailBytes_; }
  uint32_t rowBytes() const { return rowBytes_; }
  uint64_t bytesWritten() const { return written_.load(); }
  const std::filesystem::path& dir() const { return dir_; }

private:
  std::filesystem::path file(size_t chunk) const;
  void append(size_t chunk, const uint8_t* rows, size_t bytes);
  std::filesystem::path dir_;
  size_t chunks_ = 0;
  uint32_t tailBytes_ = 0, rowBytes_ = sizeof(PointRecord);
  std::atomic<uint64_t> written_{0};
};

} // namespace pointrast::io::detail

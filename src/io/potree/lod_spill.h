// Temporary chunk files of an out-of-core octree build (private to src/io): the "distribute" phase
// appends each point to its chunk's file, the "index" phase reads a chunk back whole and deletes the file.
// Threads buffer points per chunk and append whole buffers (O_APPEND makes each write land at the end
// whatever other threads do); the order of points inside a file does not matter, indexing sorts it.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "cloud/point_record.h"

namespace pointrast::io::detail {

class ChunkSpill {
public:
  // Creates dir (which must not exist yet) for `chunks` chunk files.
  ChunkSpill(std::filesystem::path dir, size_t chunks);
  // Removes dir with whatever is left in it.
  ~ChunkSpill();
  ChunkSpill(const ChunkSpill&) = delete;
  ChunkSpill& operator=(const ChunkSpill&) = delete;

  // One thread's buffers: appended to the files when they hold bufferBytes, and at flush().
  class Writer {
  public:
    Writer(ChunkSpill& spill, uint64_t bufferBytes);
    void add(uint32_t chunk, const PointRecord& record) {
      std::vector<PointRecord>& b = buffers_[chunk];
      if (b.empty()) used_.push_back(chunk);
      b.push_back(record);
      if (++buffered_ >= limit_) flush();
    }
    void flush();

  private:
    ChunkSpill& spill_;
    std::vector<std::vector<PointRecord>> buffers_;
    std::vector<uint32_t> used_;
    uint64_t buffered_ = 0, limit_ = 0;
  };

  // Reads chunk i's file (which must hold exactly `points` records) into out and deletes it.
  void read(size_t chunk, uint64_t points, std::vector<PointRecord>& out);
  uint64_t bytesWritten() const { return written_.load(); }
  const std::filesystem::path& dir() const { return dir_; }

private:
  std::filesystem::path file(size_t chunk) const;
  void append(size_t chunk, const PointRecord* records, size_t count);
  std::filesystem::path dir_;
  size_t chunks_ = 0;
  std::atomic<uint64_t> written_{0};
};

} // namespace pointrast::io::detail

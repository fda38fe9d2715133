#include "io/potree/lod_spill.h"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

#include "io/io_util.h"

namespace pointrast::io::detail {

ChunkSpill::ChunkSpill(std::filesystem::path dir, size_t chunks, uint32_t tailBytes)
    : dir_(std::move(dir)), chunks_(chunks), tailBytes_(tailBytes),
      rowBytes_(tailBytes ? uint32_t(sizeof(PointRecord) + sizeof(uint64_t) + tailBytes)
                          : uint32_t(sizeof(PointRecord))) {
  std::error_code error;
  if (!std::filesystem::create_directory(dir_, error) || error)
    fail(dir_, error ? "cannot create the folder for temporary files: " + error.message()
                     : std::string("the folder for temporary files exists already"));
}

ChunkSpill::~ChunkSpill() {
  std::error_code ignored;
  std::filesystem::remove_all(dir_, ignored);
}

std::filesystem::path ChunkSpill::file(size_t chunk) const {
  return dir_ / ("chunk-" + std::to_string(chunk) + ".bin");
}

void ChunkSpill::append(size_t chunk, const uint8_t* rows, size_t bytes) {
  const std::filesystem::path path = file(chunk);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
  if (fd < 0) fail(dir_, strFormat("cannot write temporary files: %s", std::strerror(errno)));
  const uint8_t* p = rows;
  size_t left = bytes;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int e = n < 0 ? errno : ENOSPC;
      ::close(fd);
      fail(dir_, strFormat("cannot write temporary files: %s", std::strerror(e)));
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  if (::close(fd) != 0) fail(dir_, strFormat("cannot write temporary files: %s", std::strerror(errno)));
  written_.fetch_add(bytes, std::memory_order_relaxed);
}

void ChunkSpill::read(size_t chunk, uint64_t points, std::vector<uint8_t>& out) {
  const std::filesystem::path path = file(chunk);
  out.resize(static_cast<size_t>(points * rowBytes_));
  if (points == 0) return;
  {
    InputFile in(path);
    if (in.size() != out.size()) fail(path, "a temporary chunk file changed size while the octree was built");
    in.readAt(0, out.data(), out.size());
  }
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
}

ChunkSpill::Writer::Writer(ChunkSpill& spill, uint64_t bufferBytes) : spill_(spill) {
  limit_ = std::max<uint64_t>(1, bufferBytes / spill.rowBytes_);
  buffers_.resize(spill.chunks_);
}

void ChunkSpill::Writer::flush() {
  for (uint32_t chunk : used_) {
    std::vector<uint8_t>& b = buffers_[chunk];
    spill_.append(chunk, b.data(), b.size());
    std::vector<uint8_t>().swap(b); // a buffer's peak is not kept: memory stays near the limit
  }
  used_.clear();
  buffered_ = 0;
}

} // namespace pointrast::io::detail

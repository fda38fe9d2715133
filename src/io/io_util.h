// Private helpers shared by the readers and writers in src/io/: hostile-input-safe file access, byte
// order, error messages, and the quantization of double coordinates into PointCloud's int32 + scale/offset.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <future>
#include <string>
#include <vector>

#include "base/error.h"
#include "cloud/cloud.h"

namespace pointrast::io::detail {

// Every on-disk format we read or write is little endian except binary_big_endian PLY; loads go through
// memcpy so unaligned records are fine.
static_assert(std::endian::native == std::endian::little, "io/ assumes a little-endian host");

template <class T> T loadLE(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

template <class T> T byteSwap(T v) {
  uint8_t b[sizeof(T)];
  std::memcpy(b, &v, sizeof v);
  for (size_t i = 0; i < sizeof(T) / 2; ++i)
    std::swap(b[i], b[sizeof(T) - 1 - i]);
  std::memcpy(&v, b, sizeof v);
  return v;
}

template <class T> T loadBE(const uint8_t* p) {
  return byteSwap(loadLE<T>(p));
}

template <class T> void storeLE(uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

// printf-style message; the InputError helpers below prefix it with the file name.
std::string strFormat(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

// "<file>: <message>" as an InputError. name is what the user passed (path.string()).
[[noreturn]] void fail(const std::filesystem::path& path, const std::string& message);

// One warning line on stderr ("<file>: <message>"), for data that was repaired rather than refused.
void warn(const std::filesystem::path& path, const std::string& message);

// A regular file opened for reading with positional reads. Every read is exact: a short read means the
// file changed under us or lied about its size, and throws InputError.
class InputFile {
public:
  explicit InputFile(const std::filesystem::path& path);
  ~InputFile();
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  uint64_t size() const { return size_; }
  const std::filesystem::path& path() const { return path_; }
  // Reads exactly n bytes at offset; offset + n must be <= size() (checked: InputError otherwise).
  void readAt(uint64_t offset, void* dst, size_t n) const;
  // Reads up to n bytes at offset (fewer at the end of the file); returns the count.
  size_t readSome(uint64_t offset, void* dst, size_t n) const;

private:
  std::filesystem::path path_;
  int fd_ = -1;
  uint64_t size_ = 0;
};

// Calls fn(records, first, n) for consecutive chunks of `count` fixed-size records of `stride` bytes that
// start at file offset `offset` (records [first, first + n)). A chunk holds at most chunkBytes (at least
// one record), so memory is two chunk buffers whatever the count; a helper thread reads chunk k + 1 while
// fn works on chunk k. The caller has checked that the records lie inside the file.
template <class Fn>
void forEachRecordChunk(const InputFile& file, uint64_t offset, uint64_t count, uint64_t stride,
                        uint64_t chunkBytes, Fn&& fn) {
  if (count == 0) return;
  const uint64_t perChunk = std::min<uint64_t>(count, std::max<uint64_t>(1, chunkBytes / stride));
  std::vector<uint8_t> buffers[2];
  buffers[0].resize(perChunk * stride);
  if (count > perChunk) buffers[1].resize(perChunk * stride);
  auto readChunk = [&](int b, uint64_t first) {
    uint64_t n = std::min(perChunk, count - first);
    file.readAt(offset + first * stride, buffers[b].data(), n * stride);
  };
  readChunk(0, 0);
  int b = 0;
  for (uint64_t first = 0; first < count; first += perChunk, b ^= 1) {
    uint64_t n = std::min(perChunk, count - first);
    std::future<void> next;
    if (first + n < count) next = std::async(std::launch::async, readChunk, b ^ 1, first + n);
    fn(static_cast<const uint8_t*>(buffers[b].data()), first, n);
    if (next.valid()) next.get();
  }
}

// Sequential reading with a bounded window, for formats whose records are not fixed-size (PLY lists,
// text). ensure(n) makes n bytes available at data(); it fails with InputError at the end of the file.
class BufferedReader {
public:
  BufferedReader(const InputFile& file, uint64_t start, size_t window = size_t(4) << 20);

  uint64_t position() const { return bufferStart_ + cursor_; }
  uint64_t remaining() const { return file_.size() - position(); }
  bool atEnd() const { return position() >= file_.size(); }
  // Makes at least n bytes available at data() if the file has them; returns how many are (<= n only
  // at the end of the file, never more than n is promised).
  size_t fill(size_t n);
  // As fill, but throws InputError (what: "a vertex", "a list count", ...) if fewer than n bytes remain.
  const uint8_t* require(size_t n, const char* what);
  const uint8_t* data() const { return buffer_.data() + cursor_; }
  size_t available() const { return end_ - cursor_; }
  void consume(size_t n) { cursor_ += n; }
  // Skips n bytes (may be far more than the window); InputError past the end.
  void skip(uint64_t n, const char* what);

private:
  const InputFile& file_;
  std::vector<uint8_t> buffer_;
  uint64_t bufferStart_; // file offset of buffer_[0]
  size_t cursor_ = 0;
  size_t end_ = 0;
};

// A file written under "<path>.partial" and renamed over path by commit(). If commit() is never reached
// (an exception, a write error), the destructor removes the partial file, so no half-written output is
// ever left under either name.
class PartialFile {
public:
  explicit PartialFile(std::filesystem::path target);
  ~PartialFile();
  PartialFile(const PartialFile&) = delete;
  PartialFile& operator=(const PartialFile&) = delete;

  void write(const void* data, size_t n);
  // Overwrites bytes already written (a header whose counts are known at the end); later writes append.
  void writeAt(uint64_t offset, const void* data, size_t n);
  void commit();
  const std::filesystem::path& target() const { return target_; }

private:
  [[noreturn]] void failWrite(int error);
  std::filesystem::path target_;
  std::filesystem::path partial_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

std::filesystem::path partialPath(const std::filesystem::path& target);

// Positions from text or float formats arrive as doubles; PointCloud keeps int32 + per-axis scale/offset.
// offset = bounds.min and scale = the smallest power of ten that spans the extent in kQuantSteps steps:
// the error is at most scale / 2 <= 5 * extent / kQuantSteps ~ 2.3e-9 * extent, far below float32
// precision (6e-8 relative), and powers of ten keep decimal data readable if it is written out as LAS.
inline constexpr double kQuantSteps = 2147483584.0; // 2^31 - 64: headroom below INT32_MAX for rounding

struct Quantization {
  glm::dvec3 scale{1.0};
  glm::dvec3 offset{0.0};
};
// bounds must be finite (or empty: scale 1, offset 0). Throws InputError via path if the extent overflows.
Quantization chooseQuantization(const std::filesystem::path& path, const Bounds& bounds);

// Rounds to the nearest integer, ties to even, as std::nearbyint does in the default rounding mode, but
// inline: adding and subtracting 1.5 * 2^52 leaves no fraction bits (exact for |q| < 2^51, which the clamp
// before it ensures). A call to the library's nearbyint per axis was most of the readers' quantization.
inline int32_t quantize(double v, double scale, double offset) {
  double q = (v - offset) / scale;
  // The bounds guarantee 0 <= q <= kQuantSteps; the clamp only matters for values outside them. Clamping
  // to these integers before rounding gives what rounding first would.
  q = q < -2147483648.0 ? -2147483648.0 : (q > 2147483647.0 ? 2147483647.0 : q);
  constexpr double kRoundingBias = 6755399441055744.0;
  q = (q + kRoundingBias) - kRoundingBias;
  return static_cast<int32_t>(q);
}

// Colors stored in a type wider than 8 bits are mapped to 8 bits by one rule for the whole file (PLY,
// XYZ; LAS has its own integer rule with the same outcome):
//   - float data whose values all lie in [0, 1]: v * 255 (rounded);
//   - any value above 255: 16-bit data, v / 256 (8-bit values shifted left by 8 come back exactly);
//   - otherwise 8-bit values as they are.
// Negative and NaN values become 0.
struct ColorRule {
  bool isFloat = false; // the values are floats (PLY float/double, text tokens with a '.' or exponent)
  double max = 0;       // largest value seen in the file
  int bits() const { return max > 255.0 ? 16 : 8; }
};
inline uint32_t convertColor(double v, const ColorRule& rule) {
  if (!(v > 0)) return 0;
  if (rule.isFloat && rule.max <= 1.0) return static_cast<uint32_t>(std::nearbyint(std::min(v, 1.0) * 255.0));
  double r = std::nearbyint(std::min(v, 65535.0));
  if (rule.max > 255.0) return static_cast<uint32_t>(r) >> 8;
  return static_cast<uint32_t>(std::min(r, 255.0));
}

// Exact world bounds of quantized positions: the same expression as PointCloud::world(), applied to the
// per-axis integer extremes (both ends, so a negative scale is handled).
Bounds boundsFromQuantized(const int32_t qmin[3], const int32_t qmax[3], const glm::dvec3& scale,
                           const glm::dvec3& offset);

// Lower-case extension with the dot (".las"), for detection by name.
std::string lowerExtension(const std::filesystem::path& path);

} // namespace pointrast::io::detail

// Small pieces shared by the LASzip item decoders of both generations (pointwise v2, layered v3): the
// streaming median of the last five coordinate differences, the return-number context maps, LASzip's
// byte folding and clamping, and the error a corrupt chunk raises inside a decoder.
#pragma once

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace pointrast::io::laz {

// Thrown by item decoders for bytes no encoder writes; decodeChunk() turns it into an InputError that
// names the file and the chunk.
class CorruptChunk : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};
[[noreturn]] inline void corrupt(const char* what) {
  throw CorruptChunk(what);
}

// Bytes a decoder may read past the end of its stream: LASzip's encoders pad every stream so that a
// decoder never needs to, older versions by fewer bytes. Anything beyond means the data is cut off or
// the point count is larger than what the data codes.
inline constexpr size_t kPastEndSlack = 4;

// Output records are first allocated for this many points per compressed byte (real files hold
// 0.1-0.5); the buffer doubles when the data turns out to code more. So a point count that lies costs
// no more memory than the points the data really codes before the decoder runs out of bytes.
inline constexpr uint64_t kInitialPointsPerByte = 4;

inline uint64_t initialRecordCapacity(uint64_t count, size_t compressedBytes) {
  return std::min<uint64_t>(count, std::max<uint64_t>(1024, compressedBytes * kInitialPointsPerByte));
}

// Makes room for record i (capacity counts records), doubling the buffer.
inline uint8_t* recordSlot(std::vector<uint8_t>& out, uint64_t i, uint64_t& capacity, size_t recordLength,
                           uint64_t count) {
  if (i == capacity) {
    capacity = std::min(count, capacity * 2);
    out.resize(capacity * recordLength);
  }
  return out.data() + i * recordLength;
}

// min and max without a branch. GCC compiles std::min and std::max of ints into branches where it
// judges them cheaper, which it did in some of the places Median5::add is inlined into.
inline int32_t minNoBranch(int32_t a, int32_t b) {
  return b ^ ((a ^ b) & -int32_t(a < b));
}
inline int32_t maxNoBranch(int32_t a, int32_t b) {
  return b ^ ((a ^ b) & -int32_t(a > b));
}

// Median of the last five values, maintained in a sorted window without sorting: LASzip's
// "StreamingMedian5", which alternates which end of the window a new value pushes out. Both of its
// cases drop one end of the window (the largest value while high_, else the smallest) and insert the
// new value in order among the four others, so the window is computed here without branches: slot i
// of the result is the new value clamped between the kept values i - 1 and i. LASzip's nested
// comparisons mispredicted on about half of the coordinates (the differences are noise).
class Median5 {
public:
  void reset() { *this = Median5{}; }
  int32_t get() const { return v_[2]; }
  void add(int32_t v) {
    const int32_t* w = v_ + (high_ ^ 1); // the four values kept, in order
    const int32_t w0 = w[0], w1 = w[1], w2 = w[2], w3 = w[3];
    // The end moves when the value lands on its side of the median (ties go the way LASzip's do);
    // bitwise operators, as a short-circuit would be a branch again.
    const bool high = (v < v_[2]) | ((high_ ^ 1) & (v == v_[2]));
    v_[0] = minNoBranch(w0, v);
    v_[1] = maxNoBranch(w0, minNoBranch(w1, v));
    v_[2] = maxNoBranch(w1, minNoBranch(w2, v));
    v_[3] = maxNoBranch(w2, minNoBranch(w3, v));
    v_[4] = maxNoBranch(w3, v);
    high_ = high;
  }

private:
  int32_t v_[5] = {0, 0, 0, 0, 0};
  bool high_ = true;
};

// A byte difference added back modulo 256 (LASzip U8_FOLD), and LASzip's U8_CLAMP.
inline uint8_t foldByte(int32_t v) {
  return static_cast<uint8_t>(v < 0 ? v + 256 : (v > 255 ? v - 256 : v));
}
inline int32_t clampByte(int32_t v) {
  return v < 0 ? 0 : (v > 255 ? 255 : v);
}

// Wrapping 32-bit arithmetic where LASzip relies on two's complement overflow.
inline int32_t addWrap(int32_t a, int32_t b) {
  return int32_t(uint32_t(a) + uint32_t(b));
}
inline int32_t mulWrap(int32_t a, int32_t b) {
  return int32_t(uint32_t(a) * uint32_t(b));
}

// Number of returns n and return number r mapped to a context for intensity and XY: 0..15 for the 3-bit
// fields of LAS 1.0-1.3 records (kReturnMap[n][r]), 0..5 for the 4-bit fields of LAS 1.4 records
// (kReturnMap6[n][r]). Completed for files that count from 0 or swap r and n, as LASzip's
// number_return_map and number_return_map_6ctx.
extern const uint8_t kReturnMap[8][8];
extern const uint8_t kReturnMap6[16][16];
// The context for Z: how far r is from n, capped at 7 (LASzip's number_return_level tables).
inline uint32_t returnLevel(uint32_t n, uint32_t r) {
  const uint32_t d = n > r ? n - r : r - n;
  return d < 7 ? d : 7;
}

} // namespace pointrast::io::laz

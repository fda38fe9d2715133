// Random LAS point records for the LAZ writer's tests: shaped like scans (coordinates as random walks,
// GPS times in interleaved sequences) with every awkward case mixed in.
#pragma once

#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "io/io_util.h"
#include "io/las/las_format.h"

namespace iotest {

// Records that exercise every branch of the item coders: coordinates as random walks with jumps
// (int32 extremes included), returns that count up, down and jump, GPS times in interleaved sequences
// with huge jumps and repeats, scanner channel switches, colors with equal and unequal channels, extra
// bytes that mostly stay.
inline std::vector<uint8_t> randomRecords(int pointFormat, uint16_t recordLength, uint64_t n, uint32_t seed) {
  std::mt19937_64 rng(seed);
  auto pick = [&](uint64_t k) { return rng() % k; };
  std::vector<uint8_t> out(n * recordLength);
  const bool extended = pointFormat >= 6;
  const int base = pointrast::io::detail::las::kRecordSize[size_t(pointFormat)];
  const int rgb = pointrast::io::detail::las::kRgbOffset[size_t(pointFormat)];
  const bool gps = pointFormat == 1 || pointFormat == 3 || extended;
  const int gpsAt = extended ? 22 : 20;
  int32_t xyz[3] = {0, 0, 0};
  double times[3] = {1000.0, 5e8, 3.5};
  std::vector<uint8_t> last(recordLength, 0);
  for (uint64_t i = 0; i < n; ++i) {
    uint8_t* r = out.data() + i * recordLength;
    std::memcpy(r, last.data(), recordLength);
    for (int a = 0; a < 3; ++a) {
      const uint64_t mode = pick(20);
      if (mode == 0)
        xyz[a] = pick(2) ? INT32_MIN : INT32_MAX;
      else if (mode == 1)
        xyz[a] = int32_t(uint32_t(rng()));
      else
        xyz[a] = int32_t(uint32_t(xyz[a]) + uint32_t(int32_t(pick(200)) - 100));
      pointrast::io::detail::storeLE<int32_t>(r + 4 * a, xyz[a]);
    }
    if (pick(3) == 0) pointrast::io::detail::storeLE<uint16_t>(r + 12, uint16_t(pick(4) ? pick(300) : rng()));
    if (pick(4) == 0) r[14] = uint8_t(pick(3) ? (r[14] & 0xF0) | ((r[14] + 1) & 0x0F) : rng());
    if (pick(5) == 0) r[15] = uint8_t(rng()); // flags / channel (6-10), class and flags (0-5)
    if (pick(5) == 0) r[16] = uint8_t(pick(2) ? pick(40) : rng());
    if (pick(6) == 0) r[17] = uint8_t(rng());
    if (extended) {
      if (pick(6) == 0) pointrast::io::detail::storeLE<int16_t>(r + 18, int16_t(rng()));
      if (pick(8) == 0) pointrast::io::detail::storeLE<uint16_t>(r + 20, uint16_t(rng()));
    } else {
      if (pick(8) == 0) pointrast::io::detail::storeLE<uint16_t>(r + 18, uint16_t(rng()));
    }
    if (gps) {
      const uint64_t mode = pick(10);
      double t = pointrast::io::detail::loadLE<double>(r + gpsAt);
      if (mode < 5) {
        const int s = int(pick(3));
        times[s] += (mode == 0 ? 1e-5 : 1e-6) * double(1 + pick(3));
        t = times[s];
      } else if (mode == 5) {
        t = times[0] + double(pick(1000)) * 1e3;
      } else if (mode == 6) {
        std::memcpy(&t, &times[1], 8);
        uint64_t bits;
        std::memcpy(&bits, &t, 8);
        bits ^= rng();
        std::memcpy(&t, &bits, 8);
      } // else: the same time again
      pointrast::io::detail::storeLE<double>(r + gpsAt, t);
    }
    if (rgb >= 0 && pick(3) == 0) {
      const uint16_t v = uint16_t(pick(2) ? pick(256) * 257 : rng());
      for (int c = 0; c < 3; ++c)
        pointrast::io::detail::storeLE<uint16_t>(r + rgb + 2 * c, pick(3) == 0 ? v : uint16_t(v + pick(700)));
      if (pointFormat == 8 && pick(2)) pointrast::io::detail::storeLE<uint16_t>(r + 36, uint16_t(rng()));
    }
    for (int b = base; b < recordLength; ++b)
      if (pick(4) == 0) r[b] = uint8_t(pick(2) ? r[b] + 1 : rng());
    std::memcpy(last.data(), r, recordLength);
  }
  return out;
}

} // namespace iotest

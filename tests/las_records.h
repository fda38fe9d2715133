// The point records of a LAS file read by the test itself, not by the library: what the browser tests
// compare a download or an export with.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

namespace pointrast::test {

// The point records of a LAS file (formats 0-10, legacy or 1.4 counts), each as its bytes, and the
// scale/offset to read their positions: the test's own reading, not the library's.
struct LasRecords {
  std::vector<std::string> records;
  glm::dvec3 scale{1}, offset{0};
};
inline LasRecords readLasRecords(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  LasRecords r;
  if (bytes.size() < 227 || bytes.compare(0, 4, "LASF") != 0) {
    ADD_FAILURE() << path << " is not a LAS file";
    return r;
  }
  auto u32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  auto u16 = [&](size_t at) {
    uint16_t v;
    std::memcpy(&v, bytes.data() + at, 2);
    return v;
  };
  auto f64 = [&](size_t at) {
    double v;
    std::memcpy(&v, bytes.data() + at, 8);
    return v;
  };
  const uint32_t start = u32(96), length = u16(105);
  uint64_t count = u32(107);
  if (count == 0 && bytes.size() >= 255) std::memcpy(&count, bytes.data() + 247, 8);
  r.scale = {f64(131), f64(139), f64(147)};
  r.offset = {f64(155), f64(163), f64(171)};
  if (start + count * length > bytes.size()) {
    ADD_FAILURE() << path << " is shorter than its header says";
    return r;
  }
  for (uint64_t i = 0; i < count; ++i)
    r.records.push_back(bytes.substr(start + i * length, length));
  return r;
}

// The point records of a LAS file, sorted: the file's multiset of points.
inline std::vector<std::string> sortedLasRecords(const std::string& path) {
  std::vector<std::string> records = readLasRecords(path).records;
  std::sort(records.begin(), records.end());
  return records;
}

} // namespace pointrast::test

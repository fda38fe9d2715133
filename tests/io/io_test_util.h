// Helpers shared by the io tests: data paths, temporary files, and the "read or InputError" check.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "base/error.h"
#include "base/progress.h"
#include "io/format_table.h"
#include "io/reader.h"
#include "test_data.h"

namespace iotest {

// A file or folder of the shared test data (tests/test_data.h: tests that read it start with
// POINTRAST_REQUIRE_DATA()).
inline std::filesystem::path data(const std::string& relative) {
  return pointrast::test::dataDir() / relative;
}

// The name of the format row that recognises the file ("LAS", "XYZ"...), empty when none does.
inline std::string formatOf(const std::filesystem::path& path) {
  const pointrast::io::FormatInfo* format = pointrast::io::detectFormat(path);
  return format ? format->name : "";
}

inline pointrast::io::ReadOptions quiet() {
  pointrast::io::ReadOptions o;
  o.progress = false;
  return o;
}

// A fresh directory under the system temp folder, removed with everything in it.
class TempDir {
public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("pointrast-io-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  const std::filesystem::path& path() const { return path_; }

private:
  std::filesystem::path path_;
};

// Throws when the file is missing (a test data file not beside the checkout must fail the test, not
// hand an empty buffer to code that patches bytes at fixed offsets).
inline std::vector<uint8_t> readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("test data missing: " + path.string());
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline void writeBytes(const std::filesystem::path& path, const void* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
}
inline void writeBytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  writeBytes(path, bytes.data(), bytes.size());
}
inline void writeText(const std::filesystem::path& path, const std::string& text) {
  writeBytes(path, text.data(), text.size());
}

enum class Outcome { Read, Refused };

// readCloud and probeFile on a possibly hostile file: each must either succeed or throw InputError.
// Any other exception fails the test (a crash fails the whole binary, under ASan too).
inline Outcome readOrRefuse(const std::filesystem::path& path, std::string* message = nullptr) {
  Outcome outcome = Outcome::Read;
  try {
    pointrast::PointCloud cloud = pointrast::io::readCloud(path, quiet());
    EXPECT_EQ(cloud.positions.size() % 3, 0u);
    EXPECT_TRUE(cloud.colors.empty() || cloud.colors.size() == cloud.size());
  } catch (const pointrast::InputError& e) {
    outcome = Outcome::Refused;
    if (message) *message = e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": readCloud threw a non-InputError: " << e.what();
  }
  try {
    pointrast::io::probeFile(path);
  } catch (const pointrast::InputError&) {
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": probeFile threw a non-InputError: " << e.what();
  }
  return outcome;
}

inline uint8_t channel(uint32_t rgba, int c) {
  return static_cast<uint8_t>(rgba >> (8 * c));
}

// Deterministic pseudo-random numbers for generated test data.
struct Lcg {
  uint64_t state;
  explicit Lcg(uint64_t seed) : state(seed) {}
  uint32_t next() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<uint32_t>(state >> 33);
  }
  double uniform() { return next() / 2147483648.0; } // [0, 1)
};

} // namespace iotest

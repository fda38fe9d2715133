// Where the shared test data lives: $POINTRAST_DATA_DIR when set (a GPU machine gets a copy), else the
// ../shared/data beside the checkout. A test that reads it starts with POINTRAST_REQUIRE_DATA(): without
// the data (a fresh clone) it is skipped with one line naming what is missing; where the data must be
// there ($POINTRAST_REQUIRE_DATA=1, set by scripts/test.sh on CI) that line fails the test instead.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

namespace pointrast::test {

inline std::filesystem::path dataDir() {
  if (const char* dir = std::getenv("POINTRAST_DATA_DIR"); dir && *dir) return dir;
  return POINTRAST_DATA_DIR;
}

// The pointrast binary under test: $POINTRAST_BIN when set, else the one this build made.
inline std::string pointrastBinary() {
  if (const char* bin = std::getenv("POINTRAST_BIN"); bin && *bin) return bin;
  return POINTRAST_BINARY;
}

// Whether a missing data file fails the test rather than skipping it ($POINTRAST_REQUIRE_DATA=1).
inline bool dataRequired() {
  const char* required = std::getenv("POINTRAST_REQUIRE_DATA");
  return required && std::string_view(required) == "1";
}

// Empty when `relative` (a file or folder under dataDir(); empty: the folder itself) exists, else the
// line that says what is missing and how to get it.
inline std::string missingData(const std::filesystem::path& relative = {}) {
  const std::filesystem::path path = relative.empty() ? dataDir() : dataDir() / relative;
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) return {};
  return "test data not found: " + path.string() +
         " (the data folder beside the checkout, ../shared/data, or $POINTRAST_DATA_DIR)";
}

} // namespace pointrast::test

// Skips the test (fails it under POINTRAST_REQUIRE_DATA=1) when the data folder, or the file under it named
// by the optional argument, is absent. In a test body or a fixture's SetUp.
#define POINTRAST_REQUIRE_DATA(...)                                                                          \
  do {                                                                                                       \
    if (const std::string missing_ = ::pointrast::test::missingData(__VA_ARGS__); !missing_.empty()) {       \
      if (::pointrast::test::dataRequired()) FAIL() << missing_ << "; POINTRAST_REQUIRE_DATA=1 requires it"; \
      GTEST_SKIP() << missing_;                                                                              \
    }                                                                                                        \
  } while (0)

// Where the shared test data lives: $POINTRAST_DATA_DIR when set (a GPU machine gets a copy), else the
// ../shared/data beside the checkout.
#pragma once

#include <cstdlib>
#include <filesystem>

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

} // namespace pointrast::test

// libFuzzer target for EPT datasets: the input is split into ept.json, a hierarchy file and node data
// (two little-endian u16 lengths, then the three parts), written to a folder in memory (/dev/shm) as
// ept.json, ept-hierarchy/0-0-0-0.json (and the same text as 1-0-0-0.json, so subtree references
// resolve) and ept-data/0-0-0-0.{bin,zst,laz}. The dataset is opened, its hierarchy walked and every node
// with at most 2^16 points read, then read whole and probed.
// Seeds: ept
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "cloud/octree.h"
#include "fuzz_input.h"
#include "io/ept.h"

namespace {

namespace fs = std::filesystem;

const fs::path& folder() {
  static const fs::path dir = [] {
    std::error_code ec;
    fs::path base = fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::temp_directory_path();
    fs::path d = base / ("pointrast-ept-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(d / "ept-hierarchy");
    fs::create_directories(d / "ept-data");
    return d;
  }();
  return dir;
}

void write(const fs::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pointrast::Progress::setEnabled(false);
  if (size < 4) return 0;
  size_t jsonBytes = data[0] | size_t(data[1]) << 8, hierarchyBytes = data[2] | size_t(data[3]) << 8;
  data += 4, size -= 4;
  jsonBytes = std::min(jsonBytes, size);
  hierarchyBytes = std::min(hierarchyBytes, size - jsonBytes);
  const fs::path& dir = folder();
  write(dir / "ept.json", data, jsonBytes);
  write(dir / "ept-hierarchy" / "0-0-0-0.json", data + jsonBytes, hierarchyBytes);
  write(dir / "ept-hierarchy" / "1-0-0-0.json", data + jsonBytes, hierarchyBytes);
  const uint8_t* node = data + jsonBytes + hierarchyBytes;
  const size_t nodeBytes = size - jsonBytes - hierarchyBytes;
  for (const char* ext : {".bin", ".zst", ".laz"})
    write(dir / "ept-data" / (std::string("0-0-0-0") + ext), node, nodeBytes);
  bool small = true;
  try {
    const auto source = pointrast::io::openEpt(dir);
    pointrast::lod::forEachNode(*source, [&](const pointrast::lod::NodeInfo& n) {
      // A zstd or LAZ node may truly hold millions of points in a few bytes: claims above 2^16 are
      // skipped (their memory is the claim, not a defect).
      if (n.pointCount > (1u << 16)) {
        small = false;
        return true;
      }
      if (source->readNode(n).size() != n.pointCount) __builtin_trap();
      return true;
    });
  } catch (const pointrast::InputError&) {
  }
  if (small) {
    try {
      pointrast::io::ReadOptions options;
      options.progress = false;
      pointrast::io::readEpt(dir, options);
      pointrast::io::detail::probeEpt(dir);
    } catch (const pointrast::InputError&) {
    }
  }
  return 0;
}

// libFuzzer target for EPT datasets: the input is split into ept.json, a hierarchy file and node data
// (two little-endian u16 lengths, then the three parts), written to a folder in memory (/dev/shm) as
// ept.json, ept-hierarchy/0-0-0-0.json (and the same text as 1-0-0-0.json, so subtree references
// resolve) and ept-data/0-0-0-0.{bin,zst,laz}. The dataset is opened, its hierarchy walked and every node
// with at most kMaxPoints points read, then, when every node is that small, read whole and probed.
//
// Seeds: with EPT_FUZZ_SEEDS=DIR set, the target first writes into DIR small valid datasets in this layout:
// binary and zstandard nodes, and laszip nodes of up to 100 records of the shared LAS and LAZ files
// written by pointrast's LAZ writer (laz_seeds.h):
//   EPT_FUZZ_SEEDS=seeds ./ept_fuzz -runs=0 seeds && ./ept_fuzz -dict=ept.dict -max_total_time=300 corpus
//   seeds
//
// Fuzz flags: -entropic=0
// libFuzzer's entropic schedule keeps per input the frequencies of its rarest features; over the
// decoders' tens of thousands of features that bookkeeping took about two thirds of every execution,
// and the plain schedule reached more coverage in the same time.
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "cloud/octree.h"
#include "fuzz_input.h"
#include "io/copc_ept/ept.h"
#include "laz_seeds.h"

#include <zstd.h>

namespace {

namespace fs = std::filesystem;

// Points read per node at most: 256 keep an input under a millisecond under the sanitizers, and the
// corpus of earlier runs (nodes of 200 points) stays valid.
constexpr uint64_t kMaxPoints = 256;
constexpr uint64_t kSeedPoints = 100;

// The dataset's folder, in memory, removed when the fuzzer exits normally (a crash leaves it for a look).
const fs::path& folder() {
  struct Folder {
    fs::path dir;
    Folder() {
      std::error_code ec;
      const fs::path base =
          fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::temp_directory_path();
      dir = base / ("pointrast-ept-fuzz-" + std::to_string(::getpid()));
      fs::create_directories(dir / "ept-hierarchy");
      fs::create_directories(dir / "ept-data");
    }
    ~Folder() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  };
  static const Folder instance;
  return instance.dir;
}

void write(const fs::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

std::vector<uint8_t> seedInput(const std::string& json, const std::string& hierarchy,
                               const std::vector<uint8_t>& node) {
  std::vector<uint8_t> input{uint8_t(json.size() & 0xFF), uint8_t(json.size() >> 8),
                             uint8_t(hierarchy.size() & 0xFF), uint8_t(hierarchy.size() >> 8)};
  input.insert(input.end(), json.begin(), json.end());
  input.insert(input.end(), hierarchy.begin(), hierarchy.end());
  input.insert(input.end(), node.begin(), node.end());
  return input;
}

std::string eptJson(const char* dataType, int points, const char* extraFields) {
  std::string json =
      std::string(R"({"bounds": [0, 0, 0, 10, 10, 10], "boundsConforming": [0, 0, 0, 10, 10, 10], )") +
      R"("dataType": ")" + dataType + R"(", "hierarchyType": "json", "points": )" + std::to_string(points) +
      R"(, "schema": [)";
  for (const char* axis : {"X", "Y", "Z"})
    json += std::string(*axis == 'X' ? "" : ", ") + R"({"name": ")" + axis +
            R"(", "type": "signed", "size": 4, "scale": 0.01, "offset": 0})";
  if (*extraFields) json += std::string(", ") + extraFields;
  return json + R"(], "span": 128, "version": "1.0.0"})";
}

void writeSeeds(const fs::path& dir) {
  fs::create_directories(dir);
  const char* colors = R"({"name": "Intensity", "type": "unsigned", "size": 2}, {"name": "Red", "type": )"
                       R"("unsigned", "size": 2}, {"name": "Green", "type": "unsigned", "size": 2}, )"
                       R"({"name": "Blue", "type": "unsigned", "size": 2})";
  // Three points of 20 bytes (X, Y, Z in hundredths inside the bounds, then four 16-bit fields).
  std::vector<uint8_t> points(60);
  for (size_t i = 0; i < points.size(); ++i)
    points[i] = uint8_t(i % 4 == 3 ? 0 : (i * 37) % 200);
  fuzz::writeSeed(dir / "binary", seedInput(eptJson("binary", 3, colors), R"({"0-0-0-0": 3})", points));
  // Two points of X, Y, Z alone, zstd-compressed.
  std::vector<uint8_t> zst(ZSTD_compressBound(24));
  zst.resize(ZSTD_compress(zst.data(), zst.size(), points.data(), 24, 3));
  fuzz::writeSeed(dir / "zstandard", seedInput(eptJson("zstandard", 2, ""), R"({"0-0-0-0": 2})", zst));
  // Laszip nodes: small LAZ files of the shared data's first records, in chunks of 50 points, one per
  // point format.
  int n = 0;
  bool seen[11] = {};
  for (const fuzz::SeedRecords& seed : fuzz::seedRecords(kSeedPoints)) {
    if (seen[seed.pointFormat]) continue;
    seen[seed.pointFormat] = true;
    const std::vector<uint8_t> laz = fuzz::smallLazFile(seed, 50, dir / "scratch.laz");
    const int count = int(seed.count);
    fuzz::writeSeed(
        dir / ("laszip" + std::to_string(n++)),
        seedInput(eptJson("laszip", count, colors), "{\"0-0-0-0\": " + std::to_string(count) + "}", laz));
  }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  pointrast::Progress::setEnabled(false);
  if (const char* seeds = std::getenv("EPT_FUZZ_SEEDS"); seeds && *seeds) writeSeeds(seeds);
  return 0;
}

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
      // A zstd or LAZ node may truly hold millions of points in a few bytes: claims above kMaxPoints
      // are skipped (their memory and time are the claim, not a defect).
      if (n.pointCount > kMaxPoints) {
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

// libFuzzer target for COPC hierarchies: the input becomes the point data and the hierarchy page of a
// COPC file whose header and VLRs are fixed (LAS 1.4 point format 6, root cube of half size 100, the
// root page at the start of the hierarchy EVLR). The first two bytes give the length of the point data
// part (node chunks live there, at file offsets from kChunksStart); the rest is the root page (32-byte
// entries: level, x, y, z int32, offset u64, byte size int32, point count int32). The whole hierarchy is
// walked and every node with at most kMaxPoints points decoded.
//
// Seeds: with COPC_FUZZ_SEEDS=DIR set, the target first writes into DIR inputs whose nodes are POINT14
// chunks of up to 100 records of the shared LAS and LAZ files coded by pointrast's encoder (laz_seeds.h):
// a root alone, a root and a child sharing its chunk, and a root page that references itself as a child
// page (a cycle).
//   COPC_FUZZ_SEEDS=seeds ./copc_fuzz -runs=0 seeds && ./copc_fuzz -max_total_time=300 corpus seeds
//
// Fuzz flags: -entropic=0
// libFuzzer's entropic schedule keeps per input the frequencies of its rarest features; over the
// decoders' tens of thousands of features that bookkeeping took about two thirds of every execution,
// and the plain schedule reached more coverage in the same time.
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "cloud/octree.h"
#include "fuzz_input.h"
#include "io/copc_ept/copc.h"
#include "laz_seeds.h"

namespace {

// Points decoded per node at most: 256 keep an input under a millisecond under the sanitizers, and the
// corpus of earlier runs (nodes of 200 points) stays valid.
constexpr uint32_t kMaxPoints = 256;
constexpr uint64_t kSeedPoints = 100;

template <class T> void put(std::vector<uint8_t>& b, size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof v);
}

void putVlr(std::vector<uint8_t>& file, const char* user, uint16_t record,
            const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> h(54, 0);
  std::memcpy(h.data() + 2, user, std::strlen(user));
  put<uint16_t>(h, 18, record);
  put<uint16_t>(h, 20, static_cast<uint16_t>(payload.size()));
  file.insert(file.end(), h.begin(), h.end());
  file.insert(file.end(), payload.begin(), payload.end());
}

constexpr size_t kHeader = 375, kInfo = 160, kLaszip = 40;
constexpr size_t kPointOffset = kHeader + 54 + kInfo + 54 + kLaszip;
constexpr size_t kChunksStart = kPointOffset + 8;

std::vector<uint8_t> copcFile(const uint8_t* data, size_t size) {
  const size_t split = size < 2 ? 0 : std::min<size_t>(size - 2, data[0] | size_t(data[1]) << 8);
  const uint8_t* chunks = data + 2;
  const uint8_t* page = data + 2 + split;
  const size_t pageBytes = size < 2 ? 0 : size - 2 - split;
  const uint64_t tableOffset = kChunksStart + split;
  const uint64_t evlrOffset = tableOffset + 8;

  std::vector<uint8_t> f(kHeader, 0);
  std::memcpy(f.data(), "LASF", 4);
  f[24] = 1, f[25] = 4;
  put<uint16_t>(f, 94, kHeader);
  put<uint32_t>(f, 96, kPointOffset);
  put<uint32_t>(f, 100, 2);
  f[104] = 6 | 0x80;
  put<uint16_t>(f, 105, 30);
  for (int a = 0; a < 3; ++a) {
    put<double>(f, 131 + 8 * a, 0.01);
    put<double>(f, 179 + 16 * a, 100.0);  // max
    put<double>(f, 187 + 16 * a, -100.0); // min
  }
  put<uint64_t>(f, 235, evlrOffset);
  put<uint32_t>(f, 243, 1);

  std::vector<uint8_t> info(kInfo, 0);
  put<double>(info, 24, 100.0); // half size
  put<double>(info, 32, 1.0);   // spacing
  put<uint64_t>(info, 40, evlrOffset + 60);
  put<uint64_t>(info, 48, pageBytes);
  putVlr(f, "copc", 1, info);
  std::vector<uint8_t> laszip(kLaszip + 6, 0);
  put<uint16_t>(laszip, 0, 3); // layered chunks
  laszip[4] = 3, laszip[5] = 4;
  put<uint32_t>(laszip, 12, 0xFFFFFFFFu); // variable chunks
  put<int64_t>(laszip, 16, -1);
  put<int64_t>(laszip, 24, -1);
  put<uint16_t>(laszip, 32, 1);
  put<uint16_t>(laszip, 34, 10); // POINT14, 30 bytes, version 3
  put<uint16_t>(laszip, 36, 30);
  put<uint16_t>(laszip, 38, 3);
  laszip.resize(kLaszip);
  putVlr(f, "laszip encoded", 22204, laszip);

  f.resize(kChunksStart + split + 8, 0);
  put<uint64_t>(f, kPointOffset, tableOffset);
  std::memcpy(f.data() + kChunksStart, chunks, split);
  // The chunk table: version 0, no chunks (the header's count is 0; nodes are reached by the hierarchy).
  std::vector<uint8_t> evlr(60, 0);
  std::memcpy(evlr.data() + 2, "copc", 4);
  put<uint16_t>(evlr, 18, 1000);
  put<uint64_t>(evlr, 20, pageBytes);
  f.insert(f.end(), evlr.begin(), evlr.end());
  f.insert(f.end(), page, page + pageBytes);
  return f;
}

void putEntry(std::vector<uint8_t>& page, int32_t level, int32_t x, int32_t y, int32_t z, uint64_t offset,
              int32_t bytes, int32_t points) {
  const size_t at = page.size();
  page.resize(at + 32);
  put(page, at, level), put(page, at + 4, x), put(page, at + 8, y), put(page, at + 12, z);
  put(page, at + 16, offset), put(page, at + 24, bytes), put(page, at + 28, points);
}

void writeSeeds(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  int n = 0;
  using pointrast::io::laz::encoderLayout;
  using pointrast::io::laz::kVariableChunks;
  for (const fuzz::SeedRecords& seed : fuzz::seedRecords(kSeedPoints)) {
    if (seed.pointFormat < 6) continue;
    if (n == 12) break;
    const std::vector<uint8_t> records = fuzz::convertRecords(seed, 6, 0);
    fuzz::SeedChunk chunk{encoderLayout(6, 30, kVariableChunks), {}, seed.count};
    chunk.bytes = fuzz::encodeSeedChunk(chunk.layout, records.data(), seed.count);
    const uint64_t split = chunk.bytes.size();
    const int32_t bytes = int32_t(split), points = int32_t(chunk.count);
    const uint64_t pageOffset = kChunksStart + split + 8 + 60;
    for (int variant = 0; variant < 3; ++variant) {
      std::vector<uint8_t> page;
      putEntry(page, 0, 0, 0, 0, kChunksStart, bytes, points);
      if (variant == 1) putEntry(page, 1, 1, 0, 1, kChunksStart, bytes, points);
      if (variant == 2) putEntry(page, 1, 0, 1, 1, pageOffset, 2 * 32, -1);
      std::vector<uint8_t> input{uint8_t(split & 0xFF), uint8_t(split >> 8)};
      input.insert(input.end(), chunk.bytes.begin(), chunk.bytes.end());
      input.insert(input.end(), page.begin(), page.end());
      fuzz::writeSeed(dir / ("copc" + std::to_string(n++)), input);
    }
  }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  pointrast::Progress::setEnabled(false);
  if (const char* seeds = std::getenv("COPC_FUZZ_SEEDS"); seeds && *seeds) writeSeeds(seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::vector<uint8_t> file = copcFile(data, size);
  fuzz::MemFile mem(file.data(), file.size());
  try {
    const auto source = pointrast::io::openCopc(mem.path());
    pointrast::lod::forEachNode(*source, [&](const pointrast::lod::NodeInfo& node) {
      if (node.pointCount <= kMaxPoints) {
        const std::vector<pointrast::PointRecord> records = source->readNode(node);
        if (records.size() != node.pointCount) __builtin_trap();
      }
      source->nodeBytes(node);
      return true;
    });
  } catch (const pointrast::InputError&) {
  }
  return 0;
}

// libFuzzer target for LAZ files: readLaz and its probe (LASzip VLR, chunk table, chunk decoding) on
// arbitrary bytes. A file that claims more than kMaxPoints points is skipped, so an input costs at most
// 256 points' work.
//
// Seeds: with LAZ_FUZZ_SEEDS=DIR set, the target first writes into DIR small LAZ files of up to 100
// records of every shared LAS and LAZ file (their headers and VLRs, pointrast's LAZ writer), in chunks of
// 50 points and in variable chunks, and the same records in the other point formats of their family
// (laz_seeds.h):
//   LAZ_FUZZ_SEEDS=seeds ./laz_fuzz -runs=0 seeds && ./laz_fuzz -max_total_time=300 corpus seeds
//
// Fuzz flags: -entropic=0
// libFuzzer's entropic schedule keeps per input the frequencies of its rarest features; over the
// decoders' tens of thousands of features that bookkeeping took about two thirds of every execution,
// and the plain schedule reached more coverage in the same time.
#include <cstdlib>
#include <cstring>
#include <string>

#include "fuzz_input.h"
#include "io/las/laz_reader.h"
#include "laz_seeds.h"

namespace {

// Points a file may claim: 256 keep an input under a millisecond under the sanitizers, and the corpus
// of earlier runs (files of 200 points) stays valid. LAZ codes
// identical points in a fraction of a bit each, so a small input may truly hold millions of points.
constexpr uint64_t kMaxPoints = 256;
constexpr uint64_t kSeedPoints = 100;

void writeSeeds(const std::filesystem::path& dir) {
  using pointrast::io::kVariableChunkSize;
  std::filesystem::create_directories(dir);
  int n = 0;
  for (const fuzz::SeedRecords& seed : fuzz::seedRecords(kSeedPoints)) {
    fuzz::writeSeed(dir / ("laz" + std::to_string(n++)), fuzz::smallLazFile(seed, 50, dir / "scratch.laz"));
    fuzz::writeSeed(dir / ("laz" + std::to_string(n++)),
                    fuzz::smallLazFile(seed, kVariableChunkSize, dir / "scratch.laz"));
  }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seeds = std::getenv("LAZ_FUZZ_SEEDS"); seeds && *seeds) writeSeeds(seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  uint64_t claimed = 0;
  if (size >= 111) {
    uint32_t legacy;
    std::memcpy(&legacy, data + 107, 4);
    claimed = legacy;
  }
  if (size >= 255 && data[25] >= 4) {
    uint64_t count64;
    std::memcpy(&count64, data + 247, 8);
    claimed = std::max(claimed, count64);
  }
  if (claimed > kMaxPoints) return 0;
  pointrast::io::detail::setLazThreads(1); // the fuzzer's process runs one input at a time
  return fuzz::run(
      data, size, [](const auto& path, const auto& options) { return pointrast::io::readLaz(path, options); },
      [](const auto& path) { pointrast::io::detail::probeLaz(path); });
}

// libFuzzer target for LAZ files: readLaz and its probe (LASzip VLR, chunk table, chunk decoding) on
// arbitrary bytes. The shared files are larger than the fuzzer's inputs; simple.laz (18 KB) fits whole.
// Seeds: laz
#include <cstring>

#include "fuzz_input.h"
#include "io/las/laz_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // LAZ codes identical points in a fraction of a bit each: a small input may truly hold millions of
  // points. Their memory is the claim the header makes, not a defect, so claims above 2^20 are skipped.
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
  if (claimed > (uint64_t(1) << 20)) return 0;
  pointrast::io::detail::setLazThreads(1); // the fuzzer's process runs one input at a time
  return fuzz::run(
      data, size, [](const auto& path, const auto& options) { return pointrast::io::readLaz(path, options); },
      [](const auto& path) { pointrast::io::detail::probeLaz(path); });
}

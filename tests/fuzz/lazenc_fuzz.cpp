// libFuzzer target for the LAZ encoder: random point records round-trip through the encoder and the
// decoder byte for byte. The first byte picks the item layout (point formats 0-3 pointwise, 6-8
// layered) and the count of extra bytes (0-7), the second how many chunks the records are cut into; the
// rest are the raw records (whole records only, at least one; at most kMaxPoints are coded, so an input
// costs at most 128 points' work). A decoded chunk that differs from the records encoded, or a decoder
// that refuses the encoder's bytes, is a finding.
//
// Seeds: with LAZENC_FUZZ_SEEDS=DIR set, the target first writes into DIR up to 100 records of every
// shared LAS and LAZ file in every point format of its family and with 0 or 3 extra bytes (laz_seeds.h):
//   LAZENC_FUZZ_SEEDS=seeds ./lazenc_fuzz -runs=0 seeds && ./lazenc_fuzz -max_total_time=300 corpus seeds
//
// Fuzz flags: -entropic=0
// libFuzzer's entropic schedule keeps per input the frequencies of its rarest features; over the
// decoders' tens of thousands of features that bookkeeping took about two thirds of every execution,
// and the plain schedule reached more coverage in the same time.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "io/las/las_format.h"
#include "io/las/laz_chunk.h"
#include "io/las/laz_common.h"
#include "io/las/laz_encoder.h"
#include "laz_seeds.h"

using namespace pointrast::io;

namespace {

constexpr uint64_t kMaxPoints = 128;
constexpr uint64_t kSeedPoints = 100;
const int kFormats[] = {0, 1, 2, 3, 6, 7, 8};

void writeSeeds(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  int n = 0;
  for (const fuzz::SeedRecords& seed : fuzz::seedRecords(kSeedPoints))
    for (uint8_t f = 0; f < 7; ++f)
      for (int extra : {0, 3}) {
        if (!fuzz::sameFamily(seed.pointFormat, kFormats[f])) continue;
        std::vector<uint8_t> input{uint8_t(f | extra << 5), uint8_t(n % 4)};
        const std::vector<uint8_t> records = fuzz::convertRecords(seed, kFormats[f], uint16_t(extra));
        input.insert(input.end(), records.begin(), records.end());
        fuzz::writeSeed(dir / ("lazenc" + std::to_string(n++)), input);
      }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seeds = std::getenv("LAZENC_FUZZ_SEEDS"); seeds && *seeds) writeSeeds(seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2) return 0;
  const int format = kFormats[(data[0] & 0x0F) % 7];
  const uint16_t extra = uint16_t(data[0] >> 5);
  const uint16_t rl = uint16_t(detail::las::kRecordSize[size_t(format)] + extra);
  const uint64_t count = std::min<uint64_t>((size - 2) / rl, kMaxPoints);
  if (count == 0) return 0;
  const uint8_t* records = data + 2;
  const uint64_t chunks = std::min<uint64_t>(count, 1 + data[1] % 4);

  // One encoder and decoder per layout (7 formats x 8 counts of extra bytes), kept from input to input
  // as a writer's and a reader's threads keep theirs: both reset their models per chunk, and building
  // the models anew cost more than coding a small input.
  struct Coders {
    laz::ChunkEncoder encoder;
    laz::ChunkDecoder decoder;
    explicit Coders(const laz::Layout& layout) : encoder(layout), decoder(layout) {}
  };
  static Coders* coders[7 * 8] = {};
  Coders*& slot = coders[(data[0] & 0x0F) % 7 * 8 + extra];
  if (!slot) slot = new Coders(laz::encoderLayout(format, rl, laz::kVariableChunks));
  laz::ChunkEncoder& encoder = slot->encoder;
  laz::ChunkDecoder& decoder = slot->decoder;
  std::vector<uint8_t> decoded;
  for (uint64_t c = 0, first = 0; c < chunks; ++c) {
    const uint64_t n = c + 1 == chunks ? count - first : count / chunks;
    const std::vector<uint8_t> bytes = encoder.encode(records + first * rl, n);
    try {
      decoder.decode(bytes.data(), bytes.size(), n, decoded);
    } catch (const laz::CorruptChunk&) {
      __builtin_trap(); // the decoder refused what the encoder wrote
    }
    if (decoded.size() != n * rl || std::memcmp(decoded.data(), records + first * rl, decoded.size()) != 0)
      __builtin_trap(); // the records did not come back
    first += n;
  }
  return 0;
}

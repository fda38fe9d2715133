// libFuzzer target for one LAZ chunk, past the container's checks: the first byte picks the item layout
// (pointwise point formats 0-3, layered 6-8, with or without extra bytes), the next two the claimed point
// count (at most kMaxPoints: a larger claim decodes the first kMaxPoints points, so an input costs at most
// 128 points' work however much it claims), the rest is the chunk's bytes (raw first point, layer
// table, arithmetic-coded streams). Every input decodes or throws CorruptChunk; the decoded buffer must
// hold exactly the claimed records.
//
// Seeds: with LAZCHUNK_FUZZ_SEEDS=DIR set, the target first writes into DIR the chunks of the shared LAZ
// files (up to 8 KiB) whose items match one of its layouts, and for every layout chunks of up to 100
// records of the shared files of the same family coded by pointrast's encoder (laz_seeds.h):
//   LAZCHUNK_FUZZ_SEEDS=seeds ./lazchunk_fuzz -runs=0 seeds && ./lazchunk_fuzz -max_total_time=300 corpus
//   seeds
//
// Fuzz flags: -entropic=0
// libFuzzer's entropic schedule keeps per input the frequencies of its rarest features; over the
// decoders' tens of thousands of features that bookkeeping took about two thirds of every execution,
// and the plain schedule reached more coverage in the same time.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "io/las/laz_chunk.h"
#include "io/las/laz_common.h"
#include "io/las/laz_format.h"
#include "laz_seeds.h"

namespace {

using namespace pointrast::io::laz;

// Points decoded per input at most: 128 points keep an input well under a millisecond under the
// sanitizers, and every model of the decoders still adapts (rescales) a few times.
constexpr uint64_t kMaxPoints = 128;
constexpr uint64_t kSeedPoints = 100;

int formatFor(uint8_t selector) {
  static const int kFormats[] = {0, 1, 2, 3, 6, 7, 8};
  return kFormats[(selector & 0x7F) % 7];
}

Layout layoutFor(uint8_t selector) {
  const int format = formatFor(selector);
  const bool extra = selector & 0x80;
  Layout layout;
  layout.compressor = format >= 6 ? Compressor::LayeredChunked : Compressor::PointwiseChunked;
  layout.chunkSize = kVariableChunks;
  const uint16_t version = format >= 6 ? 3 : 2;
  auto add = [&](ItemType type, uint16_t size) {
    layout.items.push_back({type, size, version});
    layout.recordLength = static_cast<uint16_t>(layout.recordLength + size);
  };
  if (format < 6) {
    add(ItemType::Point10, 20);
    if (format == 1 || format == 3) add(ItemType::GpsTime11, 8);
    if (format == 2 || format == 3) add(ItemType::Rgb12, 6);
    if (extra) add(ItemType::Byte, 3);
  } else {
    add(ItemType::Point14, 30);
    if (format == 7) add(ItemType::Rgb14, 6);
    if (format == 8) add(ItemType::RgbNir14, 8);
    if (extra) add(ItemType::Byte14, 3);
  }
  return layout;
}

bool sameItems(const Layout& a, const Layout& b) {
  if (a.compressor != b.compressor || a.recordLength != b.recordLength || a.items.size() != b.items.size())
    return false;
  for (size_t i = 0; i < a.items.size(); ++i)
    if (a.items[i].type != b.items[i].type || a.items[i].size != b.items[i].size ||
        a.items[i].version != b.items[i].version)
      return false;
  return true;
}

std::vector<uint8_t> seedInput(unsigned selector, uint64_t count, const std::vector<uint8_t>& bytes) {
  std::vector<uint8_t> input{uint8_t(selector), uint8_t((count - 1) & 0xFF), uint8_t((count - 1) >> 8)};
  input.insert(input.end(), bytes.begin(), bytes.end());
  return input;
}

void writeSeeds(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  int n = 0;
  for (const fuzz::SeedChunk& chunk : fuzz::seedChunks(8192, 4, kMaxPoints))
    for (unsigned selector = 0; selector < 256; ++selector)
      if (sameItems(layoutFor(uint8_t(selector)), chunk.layout)) {
        fuzz::writeSeed(dir / ("chunk" + std::to_string(n++)), seedInput(selector, chunk.count, chunk.bytes));
        break;
      }
  // Every layout (7 formats, with and without extra bytes), from each shared file of its family.
  const std::vector<fuzz::SeedRecords> sources = fuzz::seedRecords(kSeedPoints);
  for (unsigned selector : {0u, 1u, 2u, 3u, 4u, 5u, 6u, 0x80u, 0x81u, 0x82u, 0x83u, 0x84u, 0x85u, 0x86u}) {
    const Layout layout = layoutFor(uint8_t(selector));
    const int format = formatFor(uint8_t(selector));
    const uint16_t extra =
        uint16_t(layout.recordLength - pointrast::io::detail::las::kRecordSize[size_t(format)]);
    for (const fuzz::SeedRecords& source : sources) {
      if (!fuzz::sameFamily(source.pointFormat, format)) continue;
      const std::vector<uint8_t> records = fuzz::convertRecords(source, format, extra);
      fuzz::writeSeed(
          dir / ("encoded" + std::to_string(n++)),
          seedInput(selector, source.count, fuzz::encodeSeedChunk(layout, records.data(), source.count)));
    }
  }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* seeds = std::getenv("LAZCHUNK_FUZZ_SEEDS"); seeds && *seeds) writeSeeds(seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 3) return 0;
  const Layout layout = layoutFor(data[0]);
  const uint64_t count = std::min(kMaxPoints, 1 + (uint64_t(data[1]) | uint64_t(data[2]) << 8));
  static ChunkDecoder* decoders[256] = {};
  ChunkDecoder*& decoder = decoders[data[0]];
  if (!decoder) decoder = new ChunkDecoder(layout); // reused like a reader thread's, state reset per chunk
  std::vector<uint8_t> out;
  try {
    decoder->decode(data + 3, size - 3, count, out);
    if (out.size() != count * layout.recordLength) __builtin_trap();
  } catch (const CorruptChunk&) {
  }
  return 0;
}

// libFuzzer target for one LAZ chunk, past the container's checks: the first byte picks the item layout
// (pointwise point formats 0-3, layered 6-8, with or without extra bytes), the next two the claimed point
// count, the rest is the chunk's bytes (raw first point, layer table, arithmetic-coded streams). Every
// input decodes or throws CorruptChunk; the decoded buffer must hold exactly the claimed records.
//
// Seeds: with LAZCHUNK_FUZZ_SEEDS=DIR set, the target first writes into DIR the chunks of the shared LAZ
// files whose items match one of its layouts (laz_seeds.h):
//   LAZCHUNK_FUZZ_SEEDS=seeds ./lazchunk_fuzz -runs=0 seeds && ./lazchunk_fuzz -max_total_time=300 corpus
//   seeds
#include <cstdint>
#include <string>
#include <vector>

#include "io/las/laz_chunk.h"
#include "io/las/laz_common.h"
#include "io/las/laz_format.h"
#include "laz_seeds.h"

namespace {

using namespace pointrast::io::laz;

Layout layoutFor(uint8_t selector) {
  static const int kFormats[] = {0, 1, 2, 3, 6, 7, 8};
  const int format = kFormats[(selector & 0x7F) % 7];
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

void writeSeeds(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  int n = 0;
  for (const fuzz::SeedChunk& chunk : fuzz::seedChunks(65536 - 3, 4))
    for (unsigned selector = 0; selector < 256; ++selector)
      if (sameItems(layoutFor(uint8_t(selector)), chunk.layout)) {
        std::vector<uint8_t> input{uint8_t(selector), uint8_t((chunk.count - 1) & 0xFF),
                                   uint8_t((chunk.count - 1) >> 8)};
        input.insert(input.end(), chunk.bytes.begin(), chunk.bytes.end());
        fuzz::writeSeed(dir / ("chunk" + std::to_string(n++)), input);
        break;
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
  const uint64_t count = 1 + (uint64_t(data[1]) | uint64_t(data[2]) << 8);
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

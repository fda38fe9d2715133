// Seeds of the LAZ chunk and COPC targets: real chunks of the shared LAZ files. Those files are larger than
// the fuzzer's inputs (64 KiB), and a chunk target fed the whole file would start from container bytes
// that no layout of its own decodes; so each target writes its seeds from the chunks that fit (for
// pointwise chunks also a prefix with a count it still decodes), found in POINTRAST_DATA_DIR/laz (else
// ../shared/data/laz, beside the checkout the fuzz runner starts in).
#pragma once

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "base/error.h"
#include "io/io_util.h"
#include "io/las/laz_chunk.h"
#include "io/las/laz_common.h"
#include "io/las/laz_format.h"

namespace fuzz {

struct SeedChunk {
  pointrast::io::laz::Layout layout;
  std::vector<uint8_t> bytes;
  uint64_t count = 0; // points the bytes decode to
};

inline std::filesystem::path sharedLazDir() {
  const char* env = std::getenv("POINTRAST_DATA_DIR");
  return std::filesystem::path(env && *env ? env : "../shared/data") / "laz";
}

// Chunks of at most maxBytes from every LAZ file of the shared data, each checked to decode.
inline std::vector<SeedChunk> seedChunks(size_t maxBytes, size_t perFile) {
  namespace fs = std::filesystem;
  using namespace pointrast::io;
  const fs::path dir = sharedLazDir();
  std::vector<SeedChunk> seeds;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() != ".laz") continue;
    try {
      const detail::InputFile file(entry.path());
      const laz::LazFile lazFile = laz::openLaz(file);
      laz::ChunkDecoder decoder(lazFile.layout);
      size_t taken = 0;
      for (const laz::Chunk& chunk : lazFile.chunks) {
        if (taken == perFile) break;
        SeedChunk seed{lazFile.layout, {}, chunk.pointCount};
        size_t bytes = chunk.bytes;
        if (bytes > maxBytes) {
          // A pointwise chunk's first points need only its first bytes; a layered chunk needs every layer.
          if (lazFile.layout.layered()) continue;
          seed.count = chunk.pointCount * maxBytes / bytes / 2;
          bytes = maxBytes;
        }
        if (seed.count == 0 || seed.count > 65536) continue;
        seed.bytes.resize(bytes);
        file.readAt(chunk.offset, seed.bytes.data(), bytes);
        std::vector<uint8_t> out;
        decoder.decode(seed.bytes.data(), seed.bytes.size(), seed.count, out);
        seeds.push_back(std::move(seed));
        ++taken;
      }
    } catch (const pointrast::InputError&) {
    } catch (const laz::CorruptChunk&) {
    }
  }
  return seeds;
}

inline void writeSeed(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

} // namespace fuzz

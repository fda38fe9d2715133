// Seeds of the LAZ targets. Real inputs are larger than what a target should decode per execution
// (the shared LAZ files hold chunks of 50,000 points; a target decodes at most a few hundred points per
// input so that it runs hundreds of inputs a second), so the targets write small seeds of their own, found
// in POINTRAST_DATA_DIR (else ../shared/data, beside the checkout the fuzz runner starts in):
//   - seedChunks: real chunks of the shared LAZ files that fit (for pointwise chunks also a prefix with a
//     count it still decodes): the bytes LASzip itself wrote;
//   - seedRecords: the first few hundred point records of every shared LAS and LAZ file, to be encoded by
//     pointrast's own encoder into chunks (encodeSeedChunk) or small LAZ files (smallLazFile), also in the
//     point formats of the same family the data lacks (convertRecords).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "base/error.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/las/laz_chunk.h"
#include "io/las/laz_common.h"
#include "io/las/laz_encoder.h"
#include "io/las/laz_format.h"
#include "io/writer.h"

namespace fuzz {

struct SeedChunk {
  pointrast::io::laz::Layout layout;
  std::vector<uint8_t> bytes;
  uint64_t count = 0; // points the bytes decode to
};

inline std::filesystem::path sharedDataDir() {
  const char* env = std::getenv("POINTRAST_DATA_DIR");
  return std::filesystem::path(env && *env ? env : "../shared/data");
}

inline std::filesystem::path sharedLazDir() {
  return sharedDataDir() / "laz";
}

// Chunks of at most maxBytes and maxPoints from every LAZ file of the shared data, each checked to decode.
inline std::vector<SeedChunk> seedChunks(size_t maxBytes, size_t perFile, uint64_t maxPoints = 65536) {
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
        if (seed.count == 0 || seed.count > 65536 || seed.count > maxPoints) continue;
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

// The first point records of a shared LAS or LAZ file, with what a LAS file needs around them.
struct SeedRecords {
  std::string name;                       // the file's name
  std::vector<uint8_t> header;            // its public header block
  std::vector<std::vector<uint8_t>> vlrs; // its VLRs (header and payload) but the LASzip and COPC ones
  int pointFormat = 0;
  uint16_t recordLength = 0;
  std::vector<uint8_t> records;
  uint64_t count = 0;
};

// Up to maxPoints records of every LAS and LAZ file of the shared data whose point format pointrast can
// encode (0-3, 6-8); a LAZ file's come from its first chunk.
inline std::vector<SeedRecords> seedRecords(uint64_t maxPoints) {
  namespace fs = std::filesystem;
  using namespace pointrast::io;
  std::vector<fs::path> paths;
  std::error_code ec;
  for (const char* folder : {"las", "laz"})
    for (const fs::directory_entry& entry : fs::directory_iterator(sharedDataDir() / folder, ec))
      if (entry.path().extension() == ".las" || entry.path().extension() == ".laz")
        paths.push_back(entry.path());
  std::sort(paths.begin(), paths.end()); // the same seeds on every machine
  std::vector<SeedRecords> out;
  for (const fs::path& path : paths) {
    try {
      const detail::InputFile file(path);
      SeedRecords seed;
      seed.name = path.filename().string();
      detail::LasHeader hd;
      if (path.extension() == ".laz") {
        const laz::LazFile lazFile = laz::openLaz(file);
        if (lazFile.chunks.empty()) continue;
        hd = lazFile.header;
        laz::ChunkDecoder decoder(lazFile.layout);
        std::vector<uint8_t> bytes;
        laz::decodeChunk(file, lazFile, 0, decoder, bytes, seed.records);
        seed.count = std::min<uint64_t>(maxPoints, seed.records.size() / hd.recordLength);
      } else {
        hd = detail::readLasHeader(file);
        seed.count = std::min<uint64_t>(maxPoints, hd.pointCount);
        seed.records.resize(seed.count * hd.recordLength);
        file.readAt(hd.pointOffset, seed.records.data(), seed.records.size());
      }
      if (seed.count == 0 || !laz::canEncodePointFormat(hd.pointFormat)) continue;
      seed.records.resize(seed.count * hd.recordLength);
      seed.pointFormat = hd.pointFormat;
      seed.recordLength = hd.recordLength;
      seed.header.resize(hd.headerSize);
      file.readAt(0, seed.header.data(), seed.header.size());
      for (const detail::LasVlr& vlr : hd.vlrs) {
        if (vlr.userId == "laszip encoded" || vlr.userId == "copc") continue;
        std::vector<uint8_t> bytes(detail::las::kVlrHeaderSize + vlr.length);
        file.readAt(vlr.dataOffset - detail::las::kVlrHeaderSize, bytes.data(), bytes.size());
        seed.vlrs.push_back(std::move(bytes));
      }
      out.push_back(std::move(seed));
    } catch (const pointrast::InputError&) {
    } catch (const pointrast::io::laz::CorruptChunk&) {
    }
  }
  return out;
}

// Whether records of one point format can be made from another's: both in 0-3 or both in 6-8.
inline bool sameFamily(int a, int b) {
  return (a >= 6) == (b >= 6);
}

// The records of `seed` as point format `format` (of the same family) with `extra` extra bytes: the
// fields both formats have are copied (the extra bytes as far as both have them), the others are zero.
inline std::vector<uint8_t> convertRecords(const SeedRecords& seed, int format, uint16_t extra) {
  using pointrast::io::detail::las::kRecordSize;
  using pointrast::io::detail::las::kRgbOffset;
  const size_t from = seed.pointFormat, to = size_t(format);
  const size_t rl = kRecordSize[to] + extra, srcExtra = seed.recordLength - kRecordSize[from];
  auto gps = [](size_t f) { return f == 1 || f == 3 ? 20 : -1; }; // formats 6-8 hold it in their base
  const size_t base = to >= 6 ? 30 : 20;
  std::vector<uint8_t> out(seed.count * rl, 0);
  for (uint64_t i = 0; i < seed.count; ++i) {
    const uint8_t* src = seed.records.data() + i * seed.recordLength;
    uint8_t* dst = out.data() + i * rl;
    std::memcpy(dst, src, base);
    if (gps(from) >= 0 && gps(to) >= 0) std::memcpy(dst + gps(to), src + gps(from), 8);
    if (kRgbOffset[from] >= 0 && kRgbOffset[to] >= 0)
      std::memcpy(dst + kRgbOffset[to], src + kRgbOffset[from], 6);
    if (from == 8 && to == 8) std::memcpy(dst + 36, src + 36, 2); // near infrared
    std::memcpy(dst + kRecordSize[to], src + kRecordSize[from], std::min<size_t>(extra, srcExtra));
  }
  return out;
}

// One chunk of `count` records coded by pointrast's encoder in `layout`.
inline std::vector<uint8_t> encodeSeedChunk(const pointrast::io::laz::Layout& layout, const uint8_t* records,
                                            uint64_t count) {
  pointrast::io::laz::ChunkEncoder encoder(layout);
  return encoder.encode(records, count);
}

// A LAZ file of the seed's records with its header and VLRs, in chunks of chunkSize points
// (pointrast::io::kVariableChunkSize: chunks of 1, 2, 3... points up to the last), written through
// `scratch` (a file name that is removed again).
inline std::vector<uint8_t> smallLazFile(const SeedRecords& seed, uint32_t chunkSize,
                                         const std::filesystem::path& scratch) {
  using namespace pointrast::io;
  LasFileSetup setup;
  setup.header = seed.header;
  setup.vlrs = seed.vlrs;
  setup.pointFormat = seed.pointFormat;
  setup.recordLength = seed.recordLength;
  setup.laz = true;
  setup.chunkSize = chunkSize;
  std::filesystem::remove(scratch);
  {
    LasFileWriter writer(scratch, setup);
    if (chunkSize == kVariableChunkSize)
      for (uint64_t first = 0, n = 1; first < seed.count; first += n, ++n) {
        n = std::min(n, seed.count - first);
        writer.writeChunk(seed.records.data() + first * seed.recordLength, n);
      }
    else
      writer.write(seed.records.data(), seed.count);
    writer.commit();
  }
  std::ifstream in(scratch, std::ios::binary);
  std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::filesystem::remove(scratch);
  return bytes;
}

inline void writeSeed(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

} // namespace fuzz

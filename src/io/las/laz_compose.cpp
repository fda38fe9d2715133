#include "io/las/laz_compose.h"

#include <functional>

#include "io/io_util.h"

namespace pointrast::io {

using namespace detail;

namespace {

using Sink = std::function<void(const uint8_t*, size_t)>;

// LASzip VLR payload: the chunk size (u32) at byte 12.
constexpr size_t kLaszipChunkSizeAt = 12;

void compose(const std::filesystem::path& source, const std::vector<size_t>& picks, const Sink& write) {
  InputFile file(source);
  const laz::LazFile laz = laz::openLaz(file);
  const LasHeader& hd = laz.header;
  if (laz.layout.compressor == laz::Compressor::Pointwise)
    fail(source, "a LAZ file without chunks (LASzip 1.x) cannot be recomposed");
  uint64_t total = 0;
  for (size_t pick : picks) {
    if (pick >= laz.chunks.size())
      fail(source, strFormat("has %zu chunks, not %zu", laz.chunks.size(), pick + 1));
    total += laz.chunks[pick].pointCount;
  }

  // VLRs: every one but COPC's, the LASzip VLR switched to variable-size chunks.
  std::vector<uint8_t> vlrs;
  uint32_t vlrCount = 0;
  for (const LasVlr& vlr : hd.vlrs) {
    if (vlr.userId == "copc") continue;
    const size_t at = vlrs.size();
    vlrs.resize(at + las::kVlrHeaderSize + vlr.length);
    file.readAt(vlr.dataOffset - las::kVlrHeaderSize, vlrs.data() + at, vlrs.size() - at);
    if (vlr.userId == "laszip encoded" && vlr.recordId == 22204)
      storeLE<uint32_t>(vlrs.data() + at + las::kVlrHeaderSize + kLaszipChunkSizeAt, laz::kVariableChunks);
    ++vlrCount;
  }

  std::vector<uint8_t> header(hd.headerSize);
  file.readAt(0, header.data(), header.size());
  const uint64_t pointOffset = hd.headerSize + vlrs.size();
  if (pointOffset > UINT32_MAX) fail(source, "its VLRs are too large to recompose");
  storeLE<uint32_t>(header.data() + las::kPointOffset, uint32_t(pointOffset));
  storeLE<uint32_t>(header.data() + las::kVlrCount, vlrCount);
  // LAS 1.4: the legacy count is 0 for formats 6-10 and for counts above 2^32 - 1.
  const bool legacyFits = total <= UINT32_MAX && !las::isExtended(hd.pointFormat);
  storeLE<uint32_t>(header.data() + las::kLegacyCount, legacyFits ? uint32_t(total) : 0);
  for (int i = 0; i < 5; ++i)
    storeLE<uint32_t>(header.data() + las::kLegacyByReturn + 4 * i, 0);
  if (hd.versionMinor >= 4) {
    storeLE<uint64_t>(header.data() + las::kEvlrStart, 0);
    storeLE<uint32_t>(header.data() + las::kEvlrCount, 0);
    storeLE<uint64_t>(header.data() + las::kCount64, total);
    for (int i = 0; i < 15; ++i)
      storeLE<uint64_t>(header.data() + las::kByReturn64 + 8 * i, 0);
  }
  write(header.data(), header.size());
  write(vlrs.data(), vlrs.size());

  uint64_t chunkBytes = 0;
  std::vector<laz::Chunk> table;
  for (size_t pick : picks) {
    chunkBytes += laz.chunks[pick].bytes;
    table.push_back({0, laz.chunks[pick].bytes, 0, laz.chunks[pick].pointCount});
  }
  uint8_t tableOffset[8];
  storeLE<int64_t>(tableOffset, int64_t(pointOffset + 8 + chunkBytes));
  write(tableOffset, 8);
  std::vector<uint8_t> bytes;
  for (size_t pick : picks) {
    bytes.resize(laz.chunks[pick].bytes);
    file.readAt(laz.chunks[pick].offset, bytes.data(), bytes.size());
    write(bytes.data(), bytes.size());
  }
  const std::vector<uint8_t> encoded = laz::encodeChunkTable(table, true);
  write(encoded.data(), encoded.size());
}

} // namespace

std::vector<uint8_t> composeLaz(const std::filesystem::path& source, const std::vector<size_t>& picks) {
  std::vector<uint8_t> out;
  compose(source, picks, [&](const uint8_t* data, size_t n) { out.insert(out.end(), data, data + n); });
  return out;
}

void writeComposedLaz(const std::filesystem::path& source, const std::vector<size_t>& picks,
                      const std::filesystem::path& out) {
  PartialFile file(out);
  compose(source, picks, [&](const uint8_t* data, size_t n) { file.write(data, n); });
  file.commit();
}

} // namespace pointrast::io

#include "io/las/laz_format.h"

#include <algorithm>

#include "io/las/laz_arithmetic.h"
#include "io/las/laz_common.h"
#include "io/las/laz_integer.h"

namespace pointrast::io::laz {

using detail::fail;
using detail::InputFile;
using detail::LasHeader;
using detail::loadLE;
using detail::strFormat;

const char* itemName(ItemType type) {
  switch (type) {
  case ItemType::Byte:
    return "BYTE";
  case ItemType::Point10:
    return "POINT10";
  case ItemType::GpsTime11:
    return "GPSTIME11";
  case ItemType::Rgb12:
    return "RGB12";
  case ItemType::WavePacket13:
    return "WAVEPACKET13";
  case ItemType::Point14:
    return "POINT14";
  case ItemType::Rgb14:
    return "RGB14";
  case ItemType::RgbNir14:
    return "RGBNIR14";
  case ItemType::WavePacket14:
    return "WAVEPACKET14";
  case ItemType::Byte14:
    return "BYTE14";
  }
  return "unknown";
}

std::string Layout::describeItems() const {
  std::string s;
  for (const Item& item : items) {
    if (!s.empty()) s += ", ";
    s += strFormat("%s v%u", itemName(item.type), item.version);
    if (item.type == ItemType::Byte || item.type == ItemType::Byte14) s += strFormat(" (%u B)", item.size);
  }
  return s;
}

std::string Layout::describeCompressor() const {
  switch (compressor) {
  case Compressor::None:
    return "none";
  case Compressor::Pointwise:
    return "pointwise, one stream";
  case Compressor::PointwiseChunked:
    return "pointwise chunks";
  case Compressor::LayeredChunked:
    return "layered chunks";
  }
  return "unknown";
}

namespace {

// The LASzip VLR payload (LASzip's laszip.cpp, "unpack"): compressor u16, coder u16, version major u8,
// minor u8, revision u16, options u32, chunk size u32, number of special EVLRs i64, offset of special
// EVLRs i64, item count u16, then per item type u16, size u16, version u16.
constexpr size_t kVlrFixedBytes = 34;

// Items a point format needs, in record order (extra bytes follow as one BYTE / BYTE14 item).
std::vector<ItemType> expectedItems(int pointFormat) {
  using T = ItemType;
  switch (pointFormat) {
  case 0:
    return {T::Point10};
  case 1:
    return {T::Point10, T::GpsTime11};
  case 2:
    return {T::Point10, T::Rgb12};
  case 3:
    return {T::Point10, T::GpsTime11, T::Rgb12};
  case 4:
    return {T::Point10, T::GpsTime11, T::WavePacket13};
  case 5:
    return {T::Point10, T::GpsTime11, T::Rgb12, T::WavePacket13};
  case 6:
    return {T::Point14};
  case 7:
    return {T::Point14, T::Rgb14};
  case 8:
    return {T::Point14, T::RgbNir14};
  case 9:
    return {T::Point14, T::WavePacket14};
  case 10:
    return {T::Point14, T::RgbNir14, T::WavePacket14};
  }
  return {};
}

uint16_t fixedItemSize(ItemType type) {
  switch (type) {
  case ItemType::Point10:
    return 20;
  case ItemType::GpsTime11:
    return 8;
  case ItemType::Rgb12:
  case ItemType::Rgb14:
    return 6;
  case ItemType::RgbNir14:
    return 8;
  case ItemType::Point14:
    return 30;
  case ItemType::WavePacket13:
  case ItemType::WavePacket14:
    return 29;
  default:
    return 0;
  }
}

bool knownItemType(uint16_t type) {
  return type == 0 || (type >= 6 && type <= 14);
}

void checkItems(const std::filesystem::path& path, const Layout& layout, int pointFormat) {
  const std::vector<ItemType> expected = expectedItems(pointFormat);
  const std::string items = layout.describeItems();
  if (pointFormat == 4 || pointFormat == 5 || pointFormat == 9 || pointFormat == 10)
    fail(path, strFormat("point format %d carries waveform packets, which pointrast does not decode in LAZ "
                         "files (formats 0-3 and 6-8 are decoded)",
                         pointFormat));
  size_t n = layout.items.size();
  const bool hasExtra = n == expected.size() + 1;
  if (n != expected.size() && !hasExtra)
    fail(path, strFormat("the LASzip items (%s) do not match point format %d", items.c_str(), pointFormat));
  uint32_t total = 0;
  for (size_t i = 0; i < n; ++i) {
    const Item& item = layout.items[i];
    const bool extra = i == expected.size();
    const ItemType want = extra ? (layout.layered() ? ItemType::Byte14 : ItemType::Byte) : expected[i];
    if (item.type != want)
      fail(path, strFormat("the LASzip items (%s) do not match point format %d", items.c_str(), pointFormat));
    if (!extra && item.size != fixedItemSize(item.type))
      fail(path, strFormat("LASzip item %s has %u bytes, not %u", itemName(item.type), item.size,
                           fixedItemSize(item.type)));
    if (extra && item.size == 0) fail(path, "the LASzip extra-bytes item has 0 bytes");
    total += item.size;
  }
  if (total != layout.recordLength)
    fail(path, strFormat("the LASzip items (%s) make %u-byte records, the header says %u", items.c_str(),
                         total, layout.recordLength));
  // Item versions: 2 for pointwise chunks, 3 for layered chunks, as LASzip 2.x-3.x write them.
  for (const Item& item : layout.items) {
    if (item.version == 1 && !layout.layered())
      fail(path, "written by LASzip 1.x (item version 1), an encoding pointrast does not decode; LASzip 2 or "
                 "later re-encodes it (laszip -i FILE -o NEW.laz)");
    const uint16_t want = layout.layered() ? 3 : 2;
    if (item.version != want)
      fail(path,
           strFormat("LASzip item %s version %u is not supported (%s chunks use version %u)",
                     itemName(item.type), item.version, layout.layered() ? "layered" : "pointwise", want));
  }
}

} // namespace

Layout parseLaszipVlr(const std::filesystem::path& path, const uint8_t* data, size_t size, int pointFormat,
                      uint16_t recordLength) {
  if (size < kVlrFixedBytes)
    fail(path,
         strFormat("the LASzip VLR holds %zu bytes, fewer than the %zu it needs", size, kVlrFixedBytes));
  Layout layout;
  const uint16_t compressor = loadLE<uint16_t>(data);
  const uint16_t coder = loadLE<uint16_t>(data + 2);
  layout.versionMajor = data[4];
  layout.versionMinor = data[5];
  layout.versionRevision = loadLE<uint16_t>(data + 6);
  layout.chunkSize = loadLE<uint32_t>(data + 12);
  const uint16_t itemCount = loadLE<uint16_t>(data + 32);
  layout.recordLength = recordLength;
  if (compressor > 3) fail(path, strFormat("LASzip compressor %u is unknown", compressor));
  layout.compressor = static_cast<Compressor>(compressor);
  if (layout.compressor == Compressor::None)
    fail(path, "the LASzip VLR says the points are not compressed, but the header marks them compressed");
  if (coder != 0)
    fail(path, strFormat("LASzip coder %u is unknown (0, arithmetic coding, is the only one)", coder));
  if (size < kVlrFixedBytes + 6 * size_t(itemCount))
    fail(path, strFormat("the LASzip VLR lists %u items but holds only %zu bytes", itemCount, size));
  for (uint16_t i = 0; i < itemCount; ++i) {
    const uint8_t* p = data + kVlrFixedBytes + 6 * i;
    const uint16_t type = loadLE<uint16_t>(p);
    if (!knownItemType(type)) fail(path, strFormat("LASzip item type %u is unknown", type));
    layout.items.push_back({static_cast<ItemType>(type), loadLE<uint16_t>(p + 2), loadLE<uint16_t>(p + 4)});
  }
  if (layout.items.empty()) fail(path, "the LASzip VLR lists no items");
  const bool point14 = layout.items[0].type == ItemType::Point14;
  if (point14 != layout.layered())
    fail(path, strFormat("LASzip %s compression cannot code %s items", layout.describeCompressor().c_str(),
                         itemName(layout.items[0].type)));
  if (layout.chunkSize == 0 && layout.compressor != Compressor::Pointwise)
    fail(path, "the LASzip VLR gives a chunk size of 0 points");
  checkItems(path, layout, pointFormat);
  return layout;
}

// ---- chunk table --------------------------------------------------------------------------------------
// Version u32 (0), chunk count u32, then arithmetic-coded with one 32-bit integer codec of two
// contexts: per chunk its point count (variable chunks only, context 0) and its byte size (context 1),
// each predicted by the previous chunk's.

namespace {
// An upper bound of one chunk's coded entry: two values of at most 15 + 15 + 24 bits.
constexpr uint64_t kMaxEntryBytes = 14;
} // namespace

std::vector<uint8_t> encodeChunkTable(const std::vector<Chunk>& chunks, bool variableChunks) {
  std::vector<uint8_t> out(8, 0);
  detail::storeLE<uint32_t>(out.data(), 0);
  detail::storeLE<uint32_t>(out.data() + 4, static_cast<uint32_t>(chunks.size()));
  if (chunks.empty()) return out;
  ArithmeticEncoder enc;
  IntegerCodec ic(32, 2);
  ic.reset();
  uint32_t lastCount = 0, lastBytes = 0;
  for (const Chunk& c : chunks) {
    if (variableChunks) {
      ic.compress(enc, int32_t(lastCount), int32_t(uint32_t(c.pointCount)), 0);
      lastCount = uint32_t(c.pointCount);
    }
    ic.compress(enc, int32_t(lastBytes), int32_t(uint32_t(c.bytes)), 1);
    lastBytes = uint32_t(c.bytes);
  }
  std::vector<uint8_t> coded = enc.finish();
  out.insert(out.end(), coded.begin(), coded.end());
  return out;
}

std::vector<Chunk> decodeChunkTable(const std::filesystem::path& path, const uint8_t* data, size_t size,
                                    bool variableChunks, uint64_t maxChunks) {
  if (size < 8) fail(path, "the LAZ chunk table is cut off");
  const uint32_t version = loadLE<uint32_t>(data);
  const uint32_t count = loadLE<uint32_t>(data + 4);
  if (version != 0)
    fail(path, strFormat("LAZ chunk table version %u is unknown (0 is the only one)", version));
  if (count > maxChunks)
    fail(path, strFormat("the LAZ chunk table claims %u chunks, more than the point data can hold (%llu)",
                         count, static_cast<unsigned long long>(maxChunks)));
  std::vector<Chunk> chunks(count);
  if (count == 0) return chunks;
  ArithmeticDecoder dec;
  dec.init(data + 8, data + size);
  IntegerCodec ic(32, 2);
  ic.reset();
  uint32_t lastCount = 0, lastBytes = 0;
  for (Chunk& c : chunks) {
    if (variableChunks) {
      lastCount = uint32_t(ic.decompress(dec, int32_t(lastCount), 0));
      c.pointCount = lastCount;
    }
    lastBytes = uint32_t(ic.decompress(dec, int32_t(lastBytes), 1));
    c.bytes = lastBytes;
    if (dec.pastEnd() > kPastEndSlack) fail(path, "the LAZ chunk table is cut off or damaged");
  }
  return chunks;
}

namespace {

// Where the chunk table is: the first 8 bytes of the point data, or (-1) the last 8 bytes of the file,
// which LASzip writes when it could not seek back.
uint64_t chunkTableOffset(const InputFile& file, const LasHeader& hd, uint64_t chunksStart) {
  const std::filesystem::path& path = file.path();
  uint8_t b[8];
  file.readAt(hd.pointOffset, b, 8);
  int64_t offset = loadLE<int64_t>(b);
  if (offset == -1) {
    file.readAt(file.size() - 8, b, 8);
    offset = loadLE<int64_t>(b);
  }
  if (offset >= 0 && uint64_t(offset) + 8 == chunksStart)
    fail(path, "the LAZ chunk table is missing (the writer was interrupted before it finished the file)");
  if (offset < 0 || uint64_t(offset) < chunksStart)
    fail(path, strFormat("the LAZ chunk table offset %lld points before the point data (%llu)",
                         static_cast<long long>(offset), static_cast<unsigned long long>(chunksStart)));
  if (uint64_t(offset) > file.size() - 8)
    fail(path, strFormat("the LAZ chunk table offset %lld is past the end of the file (%llu bytes)",
                         static_cast<long long>(offset), static_cast<unsigned long long>(file.size())));
  return uint64_t(offset);
}

const detail::LasVlr& findLaszipVlr(const std::filesystem::path& path, const LasHeader& hd) {
  for (const detail::LasVlr& vlr : hd.vlrs)
    if (vlr.userId == "laszip encoded" && vlr.recordId == 22204) return vlr;
  if (hd.vlrsTruncated)
    fail(path, "the VLR list runs past the point data before the LASzip VLR (\"laszip encoded\", 22204)");
  fail(path, "compressed points but no LASzip VLR (\"laszip encoded\", 22204) says how");
}

// Assigns offsets and first points to the decoded table, checking both against the file and the header.
void placeChunks(const std::filesystem::path& path, LazFile& laz, uint64_t chunksStart) {
  const Layout& layout = laz.layout;
  const uint64_t total = laz.header.pointCount;
  uint64_t offset = chunksStart, first = 0;
  for (size_t i = 0; i < laz.chunks.size(); ++i) {
    Chunk& c = laz.chunks[i];
    if (!layout.variableChunks())
      c.pointCount = std::min<uint64_t>(layout.chunkSize, total - std::min(total, first));
    if (c.pointCount == 0)
      fail(path,
           strFormat("LAZ chunk %zu of %zu holds no points (the chunk table and the header's point count "
                     "%llu disagree)",
                     i + 1, laz.chunks.size(), static_cast<unsigned long long>(total)));
    if (c.bytes > laz.chunkTableOffset - offset)
      fail(path, strFormat("LAZ chunk %zu of %zu (%llu bytes at offset %llu) runs past the chunk table",
                           i + 1, laz.chunks.size(), static_cast<unsigned long long>(c.bytes),
                           static_cast<unsigned long long>(offset)));
    c.offset = offset;
    c.firstPoint = first;
    offset += c.bytes;
    first += c.pointCount;
  }
  if (first != total)
    fail(path, strFormat("the LAZ chunk table holds %llu points in %zu chunks, the header says %llu",
                         static_cast<unsigned long long>(first), laz.chunks.size(),
                         static_cast<unsigned long long>(total)));
}

} // namespace

LazFile openLaz(const InputFile& file) {
  const std::filesystem::path& path = file.path();
  LazFile laz;
  laz.header = detail::readLasHeader(file, true);
  const LasHeader& hd = laz.header;
  const detail::LasVlr& vlr = findLaszipVlr(path, hd);
  std::vector<uint8_t> payload(vlr.length);
  file.readAt(vlr.dataOffset, payload.data(), payload.size());
  laz.layout = parseLaszipVlr(path, payload.data(), payload.size(), hd.pointFormat, hd.recordLength);
  const Layout& layout = laz.layout;

  if (layout.compressor == Compressor::Pointwise) {
    // One stream without a chunk table (LASzip 1.x): a single chunk up to the end of the point data.
    const uint64_t end =
        hd.evlrStart > hd.pointOffset && hd.evlrStart <= file.size() ? hd.evlrStart : file.size();
    if (hd.pointCount > 0) laz.chunks.push_back({hd.pointOffset, end - hd.pointOffset, 0, hd.pointCount});
    laz.chunkTableOffset = end;
    return laz;
  }
  const uint64_t chunksStart = uint64_t(hd.pointOffset) + 8;
  if (chunksStart > file.size())
    fail(path, strFormat("the file ends inside the LAZ point data (%llu bytes)",
                         static_cast<unsigned long long>(file.size())));
  laz.chunkTableOffset = chunkTableOffset(file, hd, chunksStart);
  // A chunk holds at least its raw first point, which bounds the number of chunks the data can hold.
  const uint64_t maxChunks = (laz.chunkTableOffset - chunksStart) / layout.recordLength;
  const uint64_t tableBytes =
      std::min<uint64_t>(file.size() - laz.chunkTableOffset, 8 + (maxChunks + 1) * kMaxEntryBytes);
  std::vector<uint8_t> table(tableBytes);
  file.readAt(laz.chunkTableOffset, table.data(), table.size());
  laz.chunks = decodeChunkTable(path, table.data(), table.size(), layout.variableChunks(), maxChunks);
  placeChunks(path, laz, chunksStart);
  return laz;
}

} // namespace pointrast::io::laz

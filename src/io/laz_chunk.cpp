#include "io/laz_chunk.h"

#include <algorithm>
#include <cstring>
#include <variant>

#include "io/laz_layered.h"
#include "io/laz_pointwise.h"

namespace pointrast::io::laz {

using detail::loadLE;
using detail::strFormat;

namespace {

// Bytes a decoder may read past the end of its stream: LASzip's encoders pad every stream so that a
// decoder never needs to, older versions by fewer bytes. Anything beyond means the chunk's data is cut
// off or the point count is larger than what the data codes.
constexpr size_t kPastEndSlack = 4;

// Records are first allocated for this many points per compressed byte (real files hold 0.1-0.5), and
// the buffer doubles when the data turns out to code more.
constexpr uint64_t kInitialPointsPerByte = 4;

// Makes room for record i, doubling the buffer; capacity counts records.
inline uint8_t* recordSlot(std::vector<uint8_t>& out, uint64_t i, uint64_t& capacity, size_t recordLength,
                           uint64_t count) {
  if (i == capacity) {
    capacity = std::min(count, capacity * 2);
    out.resize(capacity * recordLength);
  }
  return out.data() + i * recordLength;
}

} // namespace

// ---- pointwise chunks (version 2 items) ---------------------------------------------------------------

struct ChunkDecoder::Pointwise {
  using AnyItem = std::variant<Point10Decoder, GpsTime11Decoder, Rgb12Decoder, Byte2Decoder>;
  std::vector<std::unique_ptr<AnyItem>> items;
  std::vector<size_t> offsets;
  ArithmeticDecoder dec;

  explicit Pointwise(const Layout& layout) {
    size_t offset = 0;
    for (const Item& item : layout.items) {
      switch (item.type) {
      case ItemType::Point10:
        items.push_back(std::make_unique<AnyItem>(std::in_place_type<Point10Decoder>));
        break;
      case ItemType::GpsTime11:
        items.push_back(std::make_unique<AnyItem>(std::in_place_type<GpsTime11Decoder>));
        break;
      case ItemType::Rgb12:
        items.push_back(std::make_unique<AnyItem>(std::in_place_type<Rgb12Decoder>));
        break;
      default: // parseLaszipVlr admits nothing else for pointwise chunks
        items.push_back(std::make_unique<AnyItem>(std::in_place_type<Byte2Decoder>, item.size));
        break;
      }
      offsets.push_back(offset);
      offset += item.size;
    }
  }

  void decode(const uint8_t* data, size_t size, uint64_t count, size_t recordLength,
              std::vector<uint8_t>& out) {
    if (size < recordLength) corrupt("its data ends inside the first point");
    uint64_t capacity = std::min<uint64_t>(count, std::max<uint64_t>(1024, size * kInitialPointsPerByte));
    out.resize(capacity * recordLength);
    std::memcpy(out.data(), data, recordLength);
    for (size_t k = 0; k < items.size(); ++k)
      std::visit([&](auto& item) { item.init(data + offsets[k]); }, *items[k]);
    dec.init(data + recordLength, data + size);
    for (uint64_t i = 1; i < count; ++i) {
      uint8_t* record = recordSlot(out, i, capacity, recordLength, count);
      for (size_t k = 0; k < items.size(); ++k)
        std::visit([&](auto& item) { item.read(dec, record + offsets[k]); }, *items[k]);
      if (dec.pastEnd() > kPastEndSlack) corrupt("its data ends before its last point");
    }
  }
};

// ---- layered chunks (version 3 items) -----------------------------------------------------------------
// Layout: the first point raw, the point count (u32), the byte size of every layer (u32 each: POINT14's
// nine, then RGB and NIR, then one per extra byte), then the layers in that order.

struct ChunkDecoder::Layered {
  Point14Decoder point;
  std::unique_ptr<Rgb14Decoder> rgb;
  std::unique_ptr<Byte14Decoder> bytes;
  size_t rgbOffset = 30, bytesOffset = 30;
  std::vector<Layer> layers;

  explicit Layered(const Layout& layout) {
    size_t offset = 0;
    for (const Item& item : layout.items) {
      if (item.type == ItemType::Rgb14 || item.type == ItemType::RgbNir14) {
        rgb = std::make_unique<Rgb14Decoder>(item.type == ItemType::RgbNir14);
        rgbOffset = offset;
      } else if (item.type == ItemType::Byte14) {
        bytes = std::make_unique<Byte14Decoder>(item.size);
        bytesOffset = offset;
      }
      offset += item.size;
    }
    layers.resize(Point14Decoder::kLayers + (rgb ? rgb->layerCount() : 0) +
                  (bytes ? bytes->layerCount() : 0));
  }

  void readLayers(const uint8_t* data, size_t size, size_t recordLength, uint64_t count) {
    const size_t header = recordLength + 4 + 4 * layers.size();
    if (size < header) corrupt("its data ends inside the layer table");
    const uint32_t chunkCount = loadLE<uint32_t>(data + recordLength);
    if (chunkCount != count)
      corrupt(strFormat("it says it holds %u points, the chunk table %llu", chunkCount,
                        static_cast<unsigned long long>(count))
                  .c_str());
    size_t offset = header;
    for (size_t i = 0; i < layers.size(); ++i) {
      const uint32_t bytesInLayer = loadLE<uint32_t>(data + recordLength + 4 + 4 * i);
      if (bytesInLayer > size - offset) corrupt("its layers run past its end");
      layers[i] = {data + offset, bytesInLayer};
      offset += bytesInLayer;
    }
  }

  size_t pastEnd() const {
    return std::max({point.pastEnd(), rgb ? rgb->pastEnd() : 0, bytes ? bytes->pastEnd() : 0});
  }

  void decode(const uint8_t* data, size_t size, uint64_t count, size_t recordLength,
              std::vector<uint8_t>& out) {
    if (size < recordLength) corrupt("its data ends inside the first point");
    readLayers(data, size, recordLength, count);
    if (count > 1 && layers[0].size == 0) corrupt("its coordinate layer is empty");
    uint64_t capacity = std::min<uint64_t>(count, std::max<uint64_t>(1024, size * kInitialPointsPerByte));
    out.resize(capacity * recordLength);
    std::memcpy(out.data(), data, recordLength);
    uint32_t context = 0;
    point.init(data, layers.data(), context);
    size_t next = Point14Decoder::kLayers;
    if (rgb) {
      rgb->init(data + rgbOffset, layers.data() + next, context);
      next += size_t(rgb->layerCount());
    }
    if (bytes) bytes->init(data + bytesOffset, layers.data() + next, context);
    for (uint64_t i = 1; i < count; ++i) {
      uint8_t* record = recordSlot(out, i, capacity, recordLength, count);
      point.read(record, context);
      if (rgb) rgb->read(record + rgbOffset, context);
      if (bytes) bytes->read(record + bytesOffset, context);
      // The coordinate layer advances with every point; the others are checked once at the end.
      if (point.pastEnd() > kPastEndSlack) corrupt("its data ends before its last point");
    }
    if (count > 1 && pastEnd() > kPastEndSlack) corrupt("one of its layers ends before its last point");
  }
};

ChunkDecoder::ChunkDecoder(const Layout& layout) : layout_(layout) {
  if (layout.layered())
    layered_ = std::make_unique<Layered>(layout);
  else
    pointwise_ = std::make_unique<Pointwise>(layout);
}

ChunkDecoder::~ChunkDecoder() = default;

void ChunkDecoder::decode(const uint8_t* data, size_t size, uint64_t count, std::vector<uint8_t>& out) {
  if (count == 0) {
    out.clear();
    return;
  }
  if (layered_)
    layered_->decode(data, size, count, layout_.recordLength, out);
  else
    pointwise_->decode(data, size, count, layout_.recordLength, out);
}

void decodeChunkAt(const detail::InputFile& file, const Chunk& chunk, const std::string& what,
                   ChunkDecoder& decoder, std::vector<uint8_t>& bytes, std::vector<uint8_t>& records) {
  // The chunk table or hierarchy placed the chunk inside the file, so its bytes are allocated and read
  // as they are; the records grow with what the data really codes.
  bytes.resize(chunk.bytes);
  file.readAt(chunk.offset, bytes.data(), bytes.size());
  try {
    decoder.decode(bytes.data(), bytes.size(), chunk.pointCount, records);
  } catch (const CorruptChunk& e) {
    detail::fail(file.path(), strFormat("%s is damaged: %s", what.c_str(), e.what()));
  }
}

void decodeChunk(const detail::InputFile& file, const LazFile& laz, size_t index, ChunkDecoder& decoder,
                 std::vector<uint8_t>& bytes, std::vector<uint8_t>& records) {
  decodeChunkAt(file, laz.chunks[index], strFormat("LAZ chunk %zu of %zu", index + 1, laz.chunks.size()),
                decoder, bytes, records);
}

} // namespace pointrast::io::laz

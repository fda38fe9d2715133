#include "io/las/laz_chunk.h"

#include <algorithm>
#include <cstring>

#include "io/las/laz_layered.h"
#include "io/las/laz_pointwise.h"

namespace pointrast::io::laz {

using detail::loadLE;
using detail::strFormat;

ChunkDecoder::ChunkDecoder(const Layout& layout) : layout_(layout) {
  if (layout.layered())
    layered_ = std::make_unique<LayeredChunkDecoder>(layout);
  else
    pointwise_ = std::make_unique<PointwiseChunkDecoder>(layout);
}

ChunkDecoder::~ChunkDecoder() = default;

void ChunkDecoder::decode(const uint8_t* data, size_t size, uint64_t count, std::vector<uint8_t>& out) {
  if (count == 0) {
    out.clear();
    return;
  }
  if (layered_)
    layered_->decode(data, size, count, out);
  else
    pointwise_->decode(data, size, count, out);
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

// Decoding one LAZ chunk into raw LAS point records (the bytes an uncompressed file would hold), so
// every consumer maps records to its own model one way, whether they came from LAS or LAZ.
//
// A ChunkDecoder owns the item decoders and their models (a few hundred KB); one per thread, reused for
// every chunk of a file. Chunks are independent, so decoders on several threads decode a file's chunks
// in any order.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "io/las/laz_format.h"

namespace pointrast::io::laz {

class PointwiseChunkDecoder;
class LayeredChunkDecoder;

class ChunkDecoder {
public:
  explicit ChunkDecoder(const Layout& layout);
  ~ChunkDecoder();
  ChunkDecoder(const ChunkDecoder&) = delete;
  ChunkDecoder& operator=(const ChunkDecoder&) = delete;

  // Decodes a chunk of `count` points from its `size` bytes at `data` into `out`, resized to
  // count * recordLength bytes. The buffer grows as points are decoded rather than by the claimed
  // count, so a count that lies costs no more memory than the points the data really codes before
  // the decoder runs out of bytes. Throws CorruptChunk with a sentence about the chunk's data.
  void decode(const uint8_t* data, size_t size, uint64_t count, std::vector<uint8_t>& out);

  const Layout& layout() const { return layout_; }

private:
  Layout layout_;
  std::unique_ptr<PointwiseChunkDecoder> pointwise_;
  std::unique_ptr<LayeredChunkDecoder> layered_;
};

// Reads chunk `index` of a LAZ file and decodes it into raw records; damaged data throws InputError
// naming the file and the chunk. `bytes` is scratch space for the compressed bytes.
void decodeChunk(const detail::InputFile& file, const LazFile& laz, size_t index, ChunkDecoder& decoder,
                 std::vector<uint8_t>& bytes, std::vector<uint8_t>& records);

// The same for a chunk described from outside the chunk table (a COPC node, an EPT node): its offset,
// byte size and point count. `what` names it in messages ("node 2-1-0-1").
void decodeChunkAt(const detail::InputFile& file, const Chunk& chunk, const std::string& what,
                   ChunkDecoder& decoder, std::vector<uint8_t>& bytes, std::vector<uint8_t>& records);

} // namespace pointrast::io::laz

// Potree 2.0 BROTLI node encoding, as PotreeConverter 2 writes it and the Potree viewer's
// DecoderWorker_brotli.js reads it: one Brotli stream per node holding the attributes one after another
// (all points' first attribute, then all points' second...). Positions are 16 bytes a point: the 48-bit
// Morton code of the high 16 bits of the uint32 coordinates, then that of the low 16 bits (each in a
// little-endian uint64; bit 3k = x bit k, 3k+1 = y, 3k+2 = z). rgb is one 48-bit Morton code of the three
// 16-bit channels in a uint64. Other attributes keep their size.
#include <brotli/decode.h>
#include <brotli/encode.h>

#include <memory>
#include <new>
#include <stdexcept>

#include "cloud/order.h"
#include "io/io_util.h"
#include "io/potree/potree_format.h"

namespace pointrast::io::potree {

using namespace detail;

namespace {

// PotreeConverter compresses at 6. Measured on the shared 2-core development machine (one thread, heavy
// load): on a 10 M-point generated terrain in 1,426 nodes, quality 3 wrote 70.2 MB in 8-9 s, 5 wrote
// 66.8 MB (-5 %) in 28-41 s, 4 was larger and slower than 3, 1 wrote 76.8 MB in 4.9 s; on autzen_trim
// 3 gave 4 % more than 5 and 6. Reading costs the same. 3 keeps BROTLI within reach of the builder's
// throughput for a few percent of size.
constexpr int kQuality = 3;
constexpr uint64_t kCode48 = (uint64_t(1) << 48) - 1;
constexpr uint64_t kMaxRatio = 4096;
constexpr uint64_t kSmallNodeBytes = uint64_t(64) << 10;

void encodeBlock(const Attribute& a, const PointRecord* records, size_t n, uint8_t* block) {
  switch (a.field) {
  case Field::Position:
    for (size_t i = 0; i < n; ++i) {
      const uint32_t x = uint32_t(records[i].x), y = uint32_t(records[i].y), z = uint32_t(records[i].z);
      storeLE<uint64_t>(block + 16 * i, mortonCode(x >> 16, y >> 16, z >> 16));
      storeLE<uint64_t>(block + 16 * i + 8, mortonCode(x & 0xFFFF, y & 0xFFFF, z & 0xFFFF));
    }
    break;
  case Field::Rgb:
    for (size_t i = 0; i < n; ++i)
      storeLE<uint64_t>(block + 8 * i, mortonCode(records[i].rgb[0], records[i].rgb[1], records[i].rgb[2]));
    break;
  case Field::Intensity:
    for (size_t i = 0; i < n; ++i)
      storeLE<uint16_t>(block + 2 * i, records[i].intensity);
    break;
  case Field::ReturnNumber:
    for (size_t i = 0; i < n; ++i)
      block[i] = records[i].returnNumber;
    break;
  case Field::Classification:
    for (size_t i = 0; i < n; ++i)
      block[i] = records[i].classification;
    break;
  case Field::PointSourceId:
    for (size_t i = 0; i < n; ++i)
      storeLE<uint16_t>(block + 2 * i, records[i].pointSourceId);
    break;
  case Field::Other:
    std::memset(block, 0, n * size_t(a.size));
    break;
  }
}

void decodeBlock(const Attribute& a, const uint8_t* block, size_t n, int32_t positionBias, PointRecord* dst) {
  uint32_t x, y, z, xl, yl, zl;
  switch (a.field) {
  case Field::Position:
    for (size_t i = 0; i < n; ++i) {
      // Bits past 48 are not part of the code (the viewer ignores them too).
      mortonDecode(loadLE<uint64_t>(block + 16 * i) & kCode48, x, y, z);
      mortonDecode(loadLE<uint64_t>(block + 16 * i + 8) & kCode48, xl, yl, zl);
      // Modular arithmetic, the inverse of the writer's uint32 subtraction.
      dst[i].x = int32_t((x << 16 | xl) - uint32_t(positionBias));
      dst[i].y = int32_t((y << 16 | yl) - uint32_t(positionBias));
      dst[i].z = int32_t((z << 16 | zl) - uint32_t(positionBias));
    }
    break;
  case Field::Rgb:
    for (size_t i = 0; i < n; ++i) {
      mortonDecode(loadLE<uint64_t>(block + 8 * i) & kCode48, x, y, z);
      dst[i].rgb[0] = uint16_t(x);
      dst[i].rgb[1] = uint16_t(y);
      dst[i].rgb[2] = uint16_t(z);
    }
    break;
  case Field::Intensity:
    for (size_t i = 0; i < n; ++i)
      dst[i].intensity = loadLE<uint16_t>(block + 2 * i);
    break;
  case Field::ReturnNumber:
    for (size_t i = 0; i < n; ++i)
      dst[i].returnNumber = block[i];
    break;
  case Field::Classification:
    for (size_t i = 0; i < n; ++i)
      dst[i].classification = block[i];
    break;
  case Field::PointSourceId:
    for (size_t i = 0; i < n; ++i)
      dst[i].pointSourceId = loadLE<uint16_t>(block + 2 * i);
    break;
  case Field::Other:
    break;
  }
}

struct DecoderDeleter {
  void operator()(BrotliDecoderState* s) const { BrotliDecoderDestroyInstance(s); }
};

// Inflates exactly `expected` bytes, failing unless the stream holds exactly that much.
std::vector<uint8_t> inflate(const uint8_t* src, uint64_t size, uint64_t expected, const std::string& where) {
  std::vector<uint8_t> out(static_cast<size_t>(expected));
  std::unique_ptr<BrotliDecoderState, DecoderDeleter> state(
      BrotliDecoderCreateInstance(nullptr, nullptr, nullptr));
  if (!state) throw std::bad_alloc();
  size_t availableIn = static_cast<size_t>(size), availableOut = out.size();
  const uint8_t* nextIn = src;
  uint8_t* nextOut = out.data();
  const BrotliDecoderResult result =
      BrotliDecoderDecompressStream(state.get(), &availableIn, &nextIn, &availableOut, &nextOut, nullptr);
  const auto bytes = [](uint64_t v) { return static_cast<unsigned long long>(v); };
  switch (result) {
  case BROTLI_DECODER_RESULT_SUCCESS:
    if (availableOut != 0)
      throw InputError(where + strFormat(" decodes to %llu bytes, not the %llu its point count needs",
                                         bytes(expected - availableOut), bytes(expected)));
    if (availableIn != 0)
      throw InputError(where +
                       strFormat(" has %llu bytes after the end of its Brotli stream", bytes(availableIn)));
    break;
  case BROTLI_DECODER_RESULT_NEEDS_MORE_OUTPUT:
    throw InputError(
        where + strFormat(" decodes to more than the %llu bytes its point count needs", bytes(expected)));
  case BROTLI_DECODER_RESULT_NEEDS_MORE_INPUT:
    throw InputError(where + " ends inside its Brotli stream (truncated)");
  case BROTLI_DECODER_RESULT_ERROR:
    throw InputError(where + " is not valid Brotli data (" +
                     BrotliDecoderErrorString(BrotliDecoderGetErrorCode(state.get())) + ")");
  }
  return out;
}

} // namespace

uint64_t brotliDecodedLimit(uint64_t compressedBytes) {
  return std::max(kSmallNodeBytes, std::min(compressedBytes, uint64_t(1) << 48) * kMaxRatio);
}

std::vector<uint8_t> encodeBrotli(const Layout& layout, const PointRecord* records, size_t n) {
  return encodeBrotli(layout, records, nullptr, n);
}

std::vector<uint8_t> encodeBrotli(const Layout& layout, const PointRecord* records, const uint8_t* tails,
                                  size_t n) {
  if (n == 0) return {};
  std::vector<uint8_t> blocks(n * static_cast<size_t>(layout.brotliStride));
  uint8_t* block = blocks.data();
  const size_t tailBytes = layout.tail.bytes();
  int at = 0; // the attribute's offset in a DEFAULT point, which names its tail slot
  for (const Attribute& a : layout.attributes) {
    encodeBlock(a, records, n, block);
    const TailSlot* slot = a.field == Field::Other && tails ? tailSlotAt(layout, at) : nullptr;
    if (slot)
      for (size_t i = 0; i < n; ++i) {
        const uint8_t* t = tails + i * tailBytes;
        if (slot->bits > 0)
          block[i] = static_cast<uint8_t>((t[slot->tailOffset] >> slot->shift) & ((1 << slot->bits) - 1));
        else
          std::memcpy(block + i * size_t(slot->size), t + slot->tailOffset, size_t(slot->size));
      }
    at += a.size;
    block += n * size_t(encodedBytes(a, PotreeEncoding::Brotli));
  }
  size_t size = BrotliEncoderMaxCompressedSize(blocks.size());
  if (size == 0) throw std::length_error("a node too large for one Brotli stream");
  std::vector<uint8_t> out(size);
  if (!BrotliEncoderCompress(kQuality, BROTLI_DEFAULT_WINDOW, BROTLI_MODE_GENERIC, blocks.size(),
                             blocks.data(), &size, out.data()))
    throw std::runtime_error("Brotli compression failed");
  out.resize(size);
  return out;
}

void decodeBrotli(const Layout& layout, const uint8_t* src, uint64_t size, size_t n, int32_t positionBias,
                  PointRecord* dst, const std::string& where, uint8_t* tails) {
  if (n == 0) return; // the viewer does not decode empty nodes either (PotreeConverter may store a byte)
  const std::vector<uint8_t> blocks = inflate(src, size, n * layout.brotliStride, where);
  const uint8_t* block = blocks.data();
  std::fill(dst, dst + n, PointRecord{});
  const size_t tailBytes = layout.tail.bytes();
  if (tails) std::memset(tails, 0, n * tailBytes);
  int at = 0;
  for (const Attribute& a : layout.attributes) {
    decodeBlock(a, block, n, positionBias, dst);
    const TailSlot* slot = a.field == Field::Other && tails ? tailSlotAt(layout, at) : nullptr;
    if (slot)
      for (size_t i = 0; i < n; ++i) {
        uint8_t* t = tails + i * tailBytes;
        if (slot->bits > 0)
          t[slot->tailOffset] = static_cast<uint8_t>(t[slot->tailOffset] |
                                                     ((block[i] & ((1 << slot->bits) - 1)) << slot->shift));
        else
          std::memcpy(t + slot->tailOffset, block + i * size_t(slot->size), size_t(slot->size));
      }
    at += a.size;
    block += n * size_t(encodedBytes(a, PotreeEncoding::Brotli));
  }
}

} // namespace pointrast::io::potree

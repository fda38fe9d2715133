// Potree 2.0 on disk, private to src/io/potree_*.cpp: hierarchy records and chunks, the attribute layout
// of metadata.json, and the two node encodings. The format is described at the top of io/potree/potree.h; the
// layout follows PotreeConverter 2 (its indexer's hierarchy and Brotli writer) and the Potree viewer's
// 2.0 loader (OctreeLoader.js, DecoderWorker.js, DecoderWorker_brotli.js).
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "cloud/octree.h"
#include "cloud/point_attributes.h"
#include "io/potree/potree.h"

namespace pointrast::io::potree {

// ---- hierarchy.bin ---------------------------------------------------------------------------------

// One node record, 22 bytes little endian:
//   0 uint8  type        0 normal (has children), 1 leaf, 2 proxy
//   1 uint8  child mask  bit i: child i exists (child index (dx << 2) | (dy << 1) | dz)
//   2 uint32 points      points stored in the node itself
//   6 int64  byte offset into octree.bin; for a proxy, into hierarchy.bin (the chunk it stands for)
//  14 int64  byte size   of the node's points; for a proxy, of that chunk
// A chunk is a node and the nodes below it down to `stepSize` levels deeper, breadth-first with
// children in index order (the order the viewer assigns records to nodes). A node of the last level that
// has children is a proxy there; its own chunk starts with its real record.
inline constexpr uint64_t kRecordBytes = 22;
enum NodeType : uint8_t { kNormal = 0, kLeaf = 1, kProxy = 2 };
// Levels below the root a hierarchy may have: cell coordinates are int32 (NodeKey); 30 levels halve a
// cube 10^9 times, far below any scanner's resolution, so deeper trees are damaged, not detailed.
inline constexpr int kMaxLevel = 30;

struct Record {
  uint8_t type = kLeaf;
  uint8_t childMask = 0;
  uint32_t pointCount = 0;
  int64_t byteOffset = 0;
  int64_t byteSize = 0;
};
void storeRecord(uint8_t* dst, const Record& record);
Record loadRecord(const uint8_t* src);

struct WrittenNode {
  lod::NodeKey key;
  uint32_t pointCount = 0;
  uint64_t byteOffset = 0, byteSize = 0; // in octree.bin
};
struct HierarchyBytes {
  std::vector<uint8_t> bytes;
  uint64_t firstChunkSize = 0;
  int depth = 0; // deepest level
};
// The hierarchy of a tree given as all its nodes (any order; the root and every node's parent present,
// each key once: asserted). Chunks are laid out root chunk first, then the others in breadth-first order
// of their roots.
HierarchyBytes buildHierarchy(std::vector<WrittenNode> nodes, int stepSize);

struct ChunkNode {
  lod::NodeKey key;
  Record record;
};
// Parses one chunk whose first record is the node `root`: records in breadth-first order, each non-proxy
// record's children taking the next places. Throws InputError (prefixed with `where`) unless the records
// describe exactly the nodes they enumerate: a valid type, no proxy first, no level past kMaxLevel, no
// record left over or missing.
std::vector<ChunkNode> parseChunk(const uint8_t* bytes, uint64_t size, const lod::NodeKey& root,
                                  const std::string& where);

// ---- attributes ------------------------------------------------------------------------------------

// The record field an attribute fills; Other: skipped when read (gps-time, user data, extra bytes...).
enum class Field { Other, Position, Rgb, Intensity, ReturnNumber, Classification, PointSourceId };

struct Attribute {
  std::string name, description, type;
  int size = 0, numElements = 0, elementSize = 0;
  std::vector<double> min, max;
  Field field = Field::Other;
};

// Where a tail field (cloud/point_attributes.h) lies in a DEFAULT point: `size` bytes at pointOffset
// copied from the tail's tailOffset, or for a bit field (bits > 0) the byte
// (tail[tailOffset] >> shift) & ((1 << bits) - 1).
struct TailSlot {
  int pointOffset = 0, tailOffset = 0, size = 0, shift = 0, bits = 0;
};

struct Layout {
  std::vector<Attribute> attributes;
  // Where points carry tails (pointrast's octrees of LAS inputs): the tail's description and where its
  // fields lie among the attributes.
  TailFormat tail;
  std::vector<TailSlot> tailSlots;
  uint64_t defaultStride = 0; // bytes per point, DEFAULT
  uint64_t brotliStride = 0;  // decoded bytes per point, BROTLI (position 16, rgb 8, others their size)
  RecordFields fields;        // which record fields the attributes fill (colorMax from rgb's max)
};
// Classifies the attributes (name, type and element count must all match for a record field) and
// computes the strides and fields.
Layout makeLayout(std::vector<Attribute> attributes);
// The attributes pointrast writes for the given fields, in this order: position, intensity, return
// number, classification, point source id, rgb (PotreeConverter's names and types).
// With tail attributes, those of io/potree/potree_attributes.h follow, in that order.
Layout writerLayout(const RecordFields& fields, const TailFormat& tail = {});
// Finds the tail's attributes (by name, as writerLayout lists them) among layout's and fills tailSlots;
// false, with the tail left empty, when one is missing or has another size.
bool attachTail(Layout& layout, const TailFormat& tail);
// Bytes one point takes in an encoded attribute block.
int encodedBytes(const Attribute& attribute, PotreeEncoding encoding);

// ---- metadata.json ---------------------------------------------------------------------------------

inline constexpr const char* kGenerator = "pointrast";

struct Metadata {
  std::string name, description, projection, generator;
  PotreeEncoding encoding = PotreeEncoding::Default;
  uint64_t points = 0;
  glm::dvec3 offset{0.0}, scale{0.001};
  double spacing = 0;
  Bounds cube;   // "boundingBox": the root's cube, which the viewer halves into children
  Bounds bounds; // tight bounds: the position attribute's min/max when stated, else empty
  uint64_t firstChunkSize = 0;
  int stepSize = 4, depth = 0;
  Layout layout;
  bool fromPointrast() const { return generator.rfind(kGenerator, 0) == 0; }
};

std::string metadataJson(const Metadata& metadata);
// Parses metadata.json defensively: every field the reader uses is checked for presence, type and range;
// one InputError sentence (prefixed with `file`) otherwise.
Metadata parseMetadata(const std::string& text, const std::filesystem::path& file);
// "DEFAULT" / "BROTLI".
const char* encodingName(PotreeEncoding encoding);

// ---- node encodings --------------------------------------------------------------------------------

// PotreeValueRanges' extremes accumulated a record at a time in six 16-byte vectors (GCC/Clang vector
// extensions; SSE2 on x86-64). As 28 scalars they need more registers than x86-64 has and cost ~106
// instructions a point (callgrind, 1 M points); this, ~20. A record is read as two overlapping 16-byte
// halves: bytes 0..15 as int32 lanes (x, y, z in lanes 0..2) and bytes 8..23 as uint16 lanes (rgb in
// 2..4, intensity 5, pointSourceId 7) and as uint8 lanes (returnNumber 12, classification 13); the
// other lanes compute values nobody reads.
class RecordExtremes {
public:
  explicit RecordExtremes(const PotreeValueRanges& start);
  void include(const PointRecord& r) {
    const auto* p = reinterpret_cast<const uint8_t*>(&r);
    I32 a;
    U16 b;
    std::memcpy(&a, p, sizeof a);
    std::memcpy(&b, p + 8, sizeof b);
    const U8 c = reinterpret_cast<U8>(b);
    posMin_ = a < posMin_ ? a : posMin_;
    posMax_ = a > posMax_ ? a : posMax_;
    u16Min_ = b < u16Min_ ? b : u16Min_;
    u16Max_ = b > u16Max_ ? b : u16Max_;
    u8Min_ = c < u8Min_ ? c : u8Min_;
    u8Max_ = c > u8Max_ ? c : u8Max_;
  }
  // The extremes into ranges (its count is left as it is).
  void into(PotreeValueRanges& ranges) const;

private:
  using I32 = int32_t __attribute__((vector_size(16)));
  using U16 = uint16_t __attribute__((vector_size(16)));
  using U8 = uint8_t __attribute__((vector_size(16)));
  I32 posMin_, posMax_;
  U16 u16Min_, u16Max_;
  U8 u8Min_, u8Max_;
};

// DEFAULT: dst holds n * layout.defaultStride bytes. Adds the records to `ranges` on the way (one pass
// over them instead of two).
void encodeDefault(const Layout& layout, const PointRecord* records, size_t n, uint8_t* dst,
                   PotreeValueRanges& ranges);
// src holds n * layout.defaultStride bytes.
void decodeDefault(const Layout& layout, const uint8_t* src, size_t n, PointRecord* dst);
// The tails' fields into (encode) or out of (decode) DEFAULT points, by layout.tailSlots; tails holds
// n * layout.tail.bytes() bytes.
void encodeDefaultTails(const Layout& layout, const uint8_t* tails, size_t n, uint8_t* dst);
// The tail slot of the attribute at `defaultOffset` in a DEFAULT point, or null.
const TailSlot* tailSlotAt(const Layout& layout, int defaultOffset);
// Adds the values of the tails' attributes to ranges.tailMin/tailMax (element after element).
void addTailRanges(const Layout& layout, const uint8_t* tails, size_t n, PotreeValueRanges& ranges);
void decodeDefaultTails(const Layout& layout, const uint8_t* src, size_t n, uint8_t* tails);

// BROTLI. Positions are stored as uint32 Morton codes of (q + positionBias) (mod 2^32); pointrast writes
// bias 0, PotreeConverter effectively +1, and the decoder subtracts the bias it is given.
std::vector<uint8_t> encodeBrotli(const Layout& layout, const PointRecord* records, size_t n);
// With the records' tails (layout.tail.bytes() each; null: zeros), their fields in their attributes'
// blocks.
std::vector<uint8_t> encodeBrotli(const Layout& layout, const PointRecord* records, const uint8_t* tails,
                                  size_t n);
// Throws InputError (prefixed with `where`) unless the stream decodes to exactly n points.
// tails: where not null, the points' tails (layout.tail.bytes() each) are decoded into it too.
void decodeBrotli(const Layout& layout, const uint8_t* src, uint64_t size, size_t n, int32_t positionBias,
                  PointRecord* dst, const std::string& where, uint8_t* tails = nullptr);
// The most decoded bytes a reader accepts from a BROTLI node of `compressedBytes`: real point data
// compresses 2-10x, so a node claiming more than 4096x (past a 64 KiB allowance for tiny nodes) lies
// about its count, or is a decompression bomb; either way it is refused before anything is allocated.
uint64_t brotliDecodedLimit(uint64_t compressedBytes);

} // namespace pointrast::io::potree

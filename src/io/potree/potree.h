// Potree 2.0 octrees (the layout of PotreeConverter 2 and of `pointrast lod`): a folder with
// metadata.json, hierarchy.bin (22-byte node records in chunks of a few levels, proxy records pointing to
// the next chunk) and octree.bin (each node's points, one after another). Read lazily: a hierarchy chunk
// when a node below it is first asked for, a node's points when they are asked for.
//
// Encodings (metadata "encoding"):
//   DEFAULT  each point's attributes one after another, in the order metadata.json lists them; positions
//            are int32 x, y, z in metadata's scale/offset.
//   BROTLI   per node one Brotli stream of the attributes one after another (all points' first attribute,
//            then all points' second...); positions as a 16-byte Morton code of the uint32 integers (the
//            high 16 bits' code, then the low 16 bits'), rgb as an 8-byte Morton code of r, g, b.
//
// Files from PotreeConverter 2 (anything without our "generator" field in metadata.json) have known
// defects, handled so:
//   - Its BROTLI writer stores each integer coordinate one quantum high: it means to subtract the node's
//     smallest integer, but that minimum starts as int64 max truncated to int32, which is -1, so it
//     subtracts -1 (coordinates are never below its offset). The reader subtracts the 1 again: exact.
//   - Its chunker turns input coordinates into integers by truncating (x - offset) / scale, so a
//     coordinate whose division lands just below an integer sits one quantum low, in both encodings. The
//     original value is lost; the reader cannot correct it (`info` says so).
//   - Some inner nodes claim points but occupy 0 bytes (its sampler moved every point up); read as empty,
//     as the Potree viewer does. Such a node behind a proxy was listed with the proxy record's count
//     before its chunk was read, so readNode() then returns fewer points than that NodeInfo said.
//   - Its out-of-core hierarchy may give a proxy record a child mask of 0; such a proxy's chunk is read
//     as soon as the proxy is listed, to learn its children.
// pointrast's writer rounds (the builder hands it exact integers), writes absolute integers in BROTLI
// (what the Potree viewer decodes: world = q * scale + offset) and marks its files with
// "generator": "pointrast". The Potree viewer decodes a BROTLI coordinate's top bits only when bits
// 11..26 of x, y and z are not all zero, so integers of 2^27 and more with those bits clear display
// wrongly there (not here).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cloud/octree.h"
#include "cloud/point_attributes.h"

namespace pointrast::io {

enum class PotreeEncoding {
  Default, // uncompressed records, attribute after attribute within a point
  Brotli,  // per node: Morton-coded positions and attributes compressed with Brotli
};

struct PotreeWriteOptions {
  PotreeEncoding encoding = PotreeEncoding::Default;
  std::string name;        // metadata "name"; empty: the folder's name
  std::string description; // metadata "description"
  // Levels per hierarchy chunk (metadata "stepSize"): a chunk holds a node and `hierarchyStepSize`
  // levels below it; nodes of its last level with children are proxies for chunks of their own.
  // PotreeConverter and the Potree viewer use 4; tests lower it to cross chunk boundaries.
  int hierarchyStepSize = 4;
  // Attributes beyond PointRecord's that the points carry as tails (cloud/point_attributes.h), written
  // as PotreeConverter names them (io/potree/potree_attributes.h) after the record fields, and
  // described in metadata.json's "lasAttributes" so that an export gives the LAS records back.
  TailFormat tail;
};

// Smallest and largest value of each record field over a set of points, for metadata.json's attribute
// ranges (and the position attribute's range, the tight bounds).
struct PotreeValueRanges {
  uint64_t count = 0;
  std::array<int32_t, 3> positionMin{INT32_MAX, INT32_MAX, INT32_MAX},
      positionMax{INT32_MIN, INT32_MIN, INT32_MIN};
  std::array<uint16_t, 3> rgbMin{UINT16_MAX, UINT16_MAX, UINT16_MAX}, rgbMax{0, 0, 0};
  uint16_t intensityMin = UINT16_MAX, intensityMax = 0;
  uint8_t returnMin = UINT8_MAX, returnMax = 0;
  uint8_t classMin = UINT8_MAX, classMax = 0;
  uint16_t sourceMin = UINT16_MAX, sourceMax = 0;
  // Of the attributes of the points' tails (PotreeWriteOptions::tail), element after element in the
  // order metadata.json lists them; empty until a tail was added.
  std::vector<double> tailMin, tailMax;

  void add(const PointRecord* records, size_t n);
  void merge(const PotreeValueRanges& other);
};

// One node's points in the octree's encoding, made by PotreeWriter::encodeNode().
struct PotreeEncodedNode {
  std::vector<uint8_t> bytes; // what octree.bin receives
  PotreeValueRanges ranges;   // of the records it was encoded from
};

// Writes an octree folder. The folder appears under its final name only at commit(): everything is
// written into a temporary sibling folder first, which the destructor removes if commit() was never
// reached, so an interrupted or failed build leaves nothing half-written behind.
class PotreeWriter {
public:
  // dir must not exist yet (InputError otherwise, naming it). metadata gives the cube, spacing,
  // scale/offset and fields; the point count and tight bounds are taken from what is written.
  PotreeWriter(std::filesystem::path dir, const lod::OctreeMetadata& metadata,
               const PotreeWriteOptions& options);
  ~PotreeWriter();
  PotreeWriter(const PotreeWriter&) = delete;
  PotreeWriter& operator=(const PotreeWriter&) = delete;

  // Folder the octree is written into until commit() (for temporary files of the caller, which it
  // removes itself before commit()).
  const std::filesystem::path& workingDir() const;

  // Appends one node's points to octree.bin. Every node of the tree is written exactly once (inner
  // nodes included, the parent of every node too); the order decides the bytes, so a deterministic
  // caller writes in a deterministic order. Not thread-safe. Records' positions are in metadata's
  // scale/offset; at most 2^32 - 1 records a node (InputError otherwise).
  void writeNode(const lod::NodeKey& key, const PointRecord* records, size_t count);
  // With the records' tails (options' tail.bytes() bytes each; null: zeros).
  void writeNode(const lod::NodeKey& key, const PointRecord* records, const uint8_t* tails, size_t count);

  // The two halves of writeNode() for callers that encode on several threads: encodeNode() is
  // thread-safe (and the slow half with BROTLI); writeEncoded() appends in the caller's order, not
  // thread-safe. writeNode(key, r, n) == writeEncoded(key, encodeNode(r, n)).
  PotreeEncodedNode encodeNode(const PointRecord* records, size_t count) const;
  PotreeEncodedNode encodeNode(const PointRecord* records, const uint8_t* tails, size_t count) const;
  void writeEncoded(const lod::NodeKey& key, const PotreeEncodedNode& node);

  // The two halves of writeEncoded() for callers that also write on several threads: place() gives the
  // node its byte range in octree.bin, in the caller's order (not thread-safe; this order alone decides
  // the bytes); writeAt() then writes its bytes there from any thread, several at once (pwrite).
  // writeEncoded(key, node) == writeAt(place(key, node), node). Every placed node is written before
  // commit().
  uint64_t place(const lod::NodeKey& key, const PotreeEncodedNode& node);
  void writeAt(uint64_t offset, const PotreeEncodedNode& node) const;

  // Writes hierarchy.bin and metadata.json and renames the folder into place. Throws InputError (with the
  // folder's name) when a write fails, e.g. a full disk.
  void commit();

  uint64_t bytesWritten() const; // octree.bin so far (placed)

private:
  struct State;
  std::unique_ptr<State> state_;
};

// Opens an octree folder (or its metadata.json). Reads metadata.json and the first hierarchy chunk;
// everything else on demand. Throws InputError for a folder that is not a Potree 2.0 octree.
std::unique_ptr<lod::NodeSource> openPotree(const std::filesystem::path& path);

// Whether path is a Potree 2.0 octree folder (or its metadata.json), by its files, without parsing: a
// folder holding a metadata.json, or a file of that name.
bool looksLikePotree(const std::filesystem::path& path);

// What metadata.json says beyond lod::OctreeMetadata, for `info` and exports.
struct PotreeAttributeInfo {
  std::string name, type;
  int size = 0, numElements = 0;
  std::vector<double> min, max; // as metadata.json states them (may be empty)
};
struct PotreeFolderInfo {
  std::string name, description, projection, encoding, generator;
  bool fromPointrast = false;  // else PotreeConverter's defects are assumed (see the top of this file)
  int stepSize = 0, depth = 0; // hierarchy "stepSize" and "depth" as stated
  uint64_t firstChunkSize = 0;
  std::vector<PotreeAttributeInfo> attributes;
};
// Reads and checks metadata.json only. Throws InputError like openPotree.
PotreeFolderInfo probePotree(const std::filesystem::path& path);

} // namespace pointrast::io

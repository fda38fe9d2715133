// COPC 1.0 output of the octree builder (copc.io): one LAS 1.4 LAZ file whose variable-size LAZ chunks are
// the octree's nodes, one chunk a node, in the order the builder finishes them.
//
// Layout of the file:
//   public header (375 B, LAS 1.4). Points with the tails of LAS records (cloud/point_attributes.h) keep
//     their input's point format where it is 6, 7 or 8, else become 8 with NIR, 7 with color, 6
//     otherwise (formats 0-5's scan angle rank converted to 0.006 degree units), with their extra
//     bytes and descriptors (an extra bytes VLR); points without tails are format 6, or 7 with color,
//     GPS times 0
//   VLR "copc" 1 (the info VLR, first, at offset 375: root cube center and half size, root spacing, the
//     root hierarchy page's offset and size, GPS time range)
//   VLR "laszip encoded" 22204 (chunk size 0xFFFFFFFF: variable chunks)
//   VLR "LASF_Projection" 2112 (the inputs' WKT coordinate system, when they have one)
//   8-byte offset of the chunk table, then the nodes' chunks, then the chunk table
//   EVLR "copc" 1000: the hierarchy pages, each page's entries sorted by key, child pages before their
//     parent, the root page last
// A page lists the nodes of `hierarchyStepSize` levels of its subtree; a node of the next level with
// children of its own is listed by a reference to its own page. Ancestors without points (every point
// of theirs went up to their own ancestors) are listed with 0 points so a reader can walk down to their
// children.
//
// The bytes depend on the points only (no creation date is written): the same build gives the same file.
// Nodes take their offsets in the builder's order, whatever thread encodes them and whenever: a node
// reserves its turn there, and offsets are handed out along the turns as their sizes become known (a
// node whose earlier turn still waits keeps its bytes until then). The nodes that span chunks are only
// copied in that order and encoded later on the indexing threads, beside the chunks' own nodes.
// The file is written into a temporary folder beside it (which also holds an out-of-core build's chunk
// files) and renamed into place at the end; an error or an interruption leaves nothing behind.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "io/potree/lod_builder.h"

namespace pointrast::io {

struct CopcWriteOptions {
  // Levels a hierarchy page lists below its own node; tests lower it to cross page boundaries.
  int hierarchyStepSize = 4;
  // The coordinate system to store (OGC WKT), empty for none.
  std::string wkt;
  // The attributes the points carry beside their records (the builder's tail), written into the records.
  TailFormat tail;
};

class CopcWriter {
public:
  // path must not exist yet (InputError otherwise). metadata gives the cube, spacing, scale/offset and
  // fields; counts and tight bounds come from the points written. averagedColors says (in the header's
  // generating software) that inner nodes hold averaged colors.
  CopcWriter(std::filesystem::path path, const lod::OctreeMetadata& metadata, bool averagedColors,
             const CopcWriteOptions& options);
  ~CopcWriter();
  CopcWriter(const CopcWriter&) = delete;
  CopcWriter& operator=(const CopcWriter&) = delete;

  // Folder for the caller's temporary files until commit() (removed with everything in it).
  const std::filesystem::path& workingDir() const;

  // One node's compressed chunk and what the header needs of its points; thread-safe.
  struct EncodedNode {
    std::vector<uint8_t> bytes;
    uint64_t count = 0;
    int32_t qmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, qmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
    std::array<uint64_t, 15> byReturn{};
    double gpsMin = 0, gpsMax = 0; // GPS time range of the points (where the tails hold one)
  };
  EncodedNode encodeNode(const lod::NodeKey& key, const PointRecord* records, size_t count) const;
  // With the records' tails (options' tail.bytes() each; null: none).
  EncodedNode encodeNode(const lod::NodeKey& key, const PointRecord* records, const uint8_t* tails,
                         size_t count) const;
  // The node's turn in the file, in the caller's order (not thread-safe with itself; the order decides
  // the bytes). Every node once.
  uint64_t reserve(const lod::NodeKey& key);
  // Hands over the encoded node of a reserved turn; thread-safe, several at once. Offsets are given in
  // turn order as soon as every earlier turn's size is known, and the bytes of the nodes that then have
  // one are written on the calling thread.
  void fill(uint64_t turn, EncodedNode node);
  // Reserves the node's turn and keeps a copy of its points, to be encoded by compressWaiting() on any
  // thread, so the caller's order never waits for an encoding (not thread-safe with reserve()).
  void writeNode(const lod::NodeKey& key, const PointRecord* records, size_t count);
  void writeNode(const lod::NodeKey& key, const PointRecord* records, const uint8_t* tails, size_t count);
  // Encodes and fills one node that writeNode() left waiting, if any; thread-safe.
  void compressWaiting();

  // Writes the chunk table, the hierarchy, the header and VLRs, and renames the file into place.
  void commit();
  uint64_t bytes() const; // the file's size after commit()

private:
  struct State;
  std::unique_ptr<State> state_;
};

class CopcNodeSink final : public lod::NodeSink {
public:
  explicit CopcNodeSink(CopcWriter& writer) : writer_(writer) {}
  void writeNode(const lod::NodeKey& key, const PointRecord* records, const uint8_t* tails,
                 size_t count) override;
  std::unique_ptr<lod::PreparedNode> prepare(const lod::NodeKey& key, const PointRecord* records,
                                             const uint8_t* tails, size_t count) const override;
  void writePrepared(const lod::NodeKey& key, lod::PreparedNode* prepared, const PointRecord* records,
                     const uint8_t* tails, size_t count) override;
  void finishPrepared(std::unique_ptr<lod::PreparedNode> prepared) const override;

private:
  CopcWriter& writer_;
};

struct CopcBuildReport {
  LodBuildReport build; // its phases end with "commit" (chunk table, hierarchy, header, rename)
  uint64_t bytes = 0;   // the file's size
};

// The WKT coordinate system of the inputs (their "LASF_Projection" 2112 VLRs), empty when none has one.
// Inputs with different ones are refused (InputError); an input with a GeoTIFF system only is warned
// about (COPC stores WKT).
std::string inputsWkt(const std::vector<std::filesystem::path>& inputs);

// Builds the octree of `inputs` into the COPC file `output` (which must not exist). The nodes and their
// points are those buildPotree() writes from the same inputs and options.
CopcBuildReport buildCopc(const std::vector<std::filesystem::path>& inputs,
                          const std::filesystem::path& output, const LodBuildOptions& options,
                          CopcWriteOptions writeOptions = {});

} // namespace pointrast::io

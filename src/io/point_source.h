// Streaming access to the points of one input file, for work that must not hold the whole cloud in
// memory (the octree builder, LAZ decoding into the reader). A file is cut into pieces that decode on
// their own: ranges of ~1 M records for LAS, one chunk each for LAZ, the whole file for formats without
// random access (PLY, XYZ: read once, then served from memory). readPiece() may be called from several
// threads at once, so a caller decodes pieces on all cores and keeps them in file order by index.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cloud/cloud.h"
#include "cloud/point_attributes.h"
#include "cloud/point_record.h"

namespace pointrast::io {

struct PointSourceInfo {
  std::string source;     // file name, for messages
  uint64_t pointCount = 0; // exact: the sum of the pieces' counts
  Bounds bounds;          // the header's bounds where the format has them (LAS, LAZ), else computed
  glm::dvec3 scale{0.001}; // records' positions: world = q * scale + offset
  glm::dvec3 offset{0.0};
  RecordFields fields;
};

struct PointPiece {
  uint64_t first = 0; // index of the piece's first point in the file
  uint64_t count = 0;
};

class PointSource {
public:
  virtual ~PointSource() = default;
  virtual const PointSourceInfo& info() const = 0;
  virtual const std::vector<PointPiece>& pieces() const = 0;
  // Replaces out with the records of piece i. Thread-safe. Throws InputError naming the file for damaged
  // data (a short or corrupt piece), never returns fewer records than the piece claims.
  virtual void readPiece(size_t i, std::vector<PointRecord>& out) const = 0;
  // Bytes of the file the piece occupies (for throughput figures), 0 when not known.
  virtual uint64_t pieceBytes(size_t i) const = 0;

  // The attributes beyond PointRecord's that the records carry (cloud/point_attributes.h); nothing
  // (attributes.any() false) for sources without them.
  virtual TailFormat tailFormat() const { return {}; }
  // readPiece() plus each record's tail in `layout` (whose fields include the source's; fields it lacks
  // are zero), layout.bytes bytes a record, one after another.
  virtual void readPieceTails(size_t i, std::vector<PointRecord>& out, const TailFormat& layout,
                              std::vector<uint8_t>& tails) const {
    readPiece(i, out);
    tails.assign(out.size() * layout.bytes(), 0);
  }
};

// Opens any point format readCloud() reads. Throws InputError.
std::unique_ptr<PointSource> openPointSource(const std::filesystem::path& path);

} // namespace pointrast::io

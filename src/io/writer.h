// Writers. Each writes to "<path>.partial" and renames over path only when everything was written, so a
// failure (disk full, bad input) never leaves a half-written file under the requested name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>

#include "cloud/cloud.h"
#include "cloud/octree.h"
#include "cloud/point_record.h"

namespace pointrast::io {

enum class LasFlavor {
  Las12Pf2, // LAS 1.2, point format 2 (RGB, no GPS time): 26 B records
  Las12Pf3, // LAS 1.2, point format 3 (GPS time + RGB): 34 B records
  Las14Pf7, // LAS 1.4, point format 7 (64-bit counts): 36 B records
};

// Writes the cloud with its own scale/offset. Colors are written 16-bit (v * 257 = v << 8 | v). LAS 1.2
// can hold at most 2^32 - 1 points; more needs Las14Pf7 (InputError otherwise).
void writeLas(const std::filesystem::path& path, const PointCloud& cloud, LasFlavor flavor);

// Streams point records into a LAS file: the records' integers with the given scale/offset, their 16-bit
// colors and point source ids as stored, the fields' attributes (zero where a field is off; return
// number 1). For exports that do not hold the whole cloud at once. The header, with counts and bounds
// from the points, is written by commit(); without commit() nothing is left behind.
class LasRecordWriter {
public:
  LasRecordWriter(const std::filesystem::path& path, const glm::dvec3& scale, const glm::dvec3& offset,
                  const RecordFields& fields, LasFlavor flavor);
  ~LasRecordWriter();
  LasRecordWriter(const LasRecordWriter&) = delete;
  LasRecordWriter& operator=(const LasRecordWriter&) = delete;

  void write(const PointRecord* records, size_t count); // InputError past LAS 1.2's 2^32 - 1 points
  uint64_t pointsWritten() const;
  void commit();

private:
  struct State;
  std::unique_ptr<State> state_;
};

// Exports every point of an octree as LAS through LasRecordWriter, exactly (the source's integers,
// scale/offset and 16-bit colors): nodes in forEachNode order, decoded on all cores a batch at a time, so
// memory stays a few batches of nodes whatever the octree's size. Returns the points written.
uint64_t writeLasFromOctree(const std::filesystem::path& path, lod::NodeSource& source, LasFlavor flavor,
                        bool progress);

// Writes RGBA8 pixels (row 0 = top) as an 8-bit RGB PNG (alpha dropped).
void writePng(const std::filesystem::path& path, uint32_t width, uint32_t height, const uint32_t* rgba);

} // namespace pointrast::io

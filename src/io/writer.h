// Writers. Each writes to "<path>.partial" and renames over path only when everything was written, so a
// failure (disk full, bad input) never leaves a half-written file under the requested name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "cloud/cloud.h"
#include "cloud/octree.h"
#include "cloud/point_filter.h"
#include "cloud/point_record.h"

namespace pointrast::io {

enum class LasFlavor {
  Las12Pf2, // LAS 1.2, point format 2 (RGB, no GPS time): 26 B records
  Las12Pf3, // LAS 1.2, point format 3 (GPS time + RGB): 34 B records
  Las14Pf7, // LAS 1.4, point format 7 (64-bit counts): 36 B records
};

// LAS or LAZ by the output's extension: ".laz" writes compressed points (LASzip chunks, see
// las/laz_encoder.h), anything else uncompressed LAS.
bool isLazPath(const std::filesystem::path& path);

// Writes the cloud with its own scale/offset. Colors are written 16-bit (v * 257 = v << 8 | v). LAS 1.2
// can hold at most 2^32 - 1 points; more needs Las14Pf7 (InputError otherwise).
void writeLas(const std::filesystem::path& path, const PointCloud& cloud, LasFlavor flavor);

// Streams point records into a LAS (or, by the extension, LAZ) file: the records' integers with the
// given scale/offset, their 16-bit colors and point source ids as stored, the fields' attributes (zero
// where a field is off; return number 1). For exports that do not hold the whole cloud at once. The
// header, with counts and bounds from the points, is written by commit(); without commit() nothing is
// left behind.
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

// Writes raw LAS point records, as an uncompressed LAS or a LAZ file, with a given header, VLRs and
// EVLRs: what a lossless conversion of a LAS, LAZ or COPC file needs. The header's counts, points by
// return, bounds, offsets and point format byte are rewritten from the records at commit(); its
// scale/offset must be finite (InputError otherwise). LAZ: chunks of chunkSize points (or one chunk
// per writeChunk() call with kVariableChunkSize), encoded in parallel on all cores.
struct LasFileSetup {
  std::vector<uint8_t> header;             // the public header block, 227 bytes or more
  std::vector<std::vector<uint8_t>> vlrs;  // each VLR's 54-byte header and payload (no LASzip VLR)
  std::vector<std::vector<uint8_t>> evlrs; // LAS 1.4: each EVLR's 60-byte header and payload
  int pointFormat = 3;
  uint16_t recordLength = 34; // the format's size plus extra bytes
  bool laz = false;
  uint32_t chunkSize = 50000;
};
inline constexpr uint32_t kVariableChunkSize = 0xFFFFFFFFu;

class LasFileWriter {
public:
  LasFileWriter(const std::filesystem::path& path, LasFileSetup setup);
  ~LasFileWriter();
  LasFileWriter(const LasFileWriter&) = delete;
  LasFileWriter& operator=(const LasFileWriter&) = delete;

  // count records of setup.recordLength bytes each.
  void write(const uint8_t* records, uint64_t count);
  // Variable-size chunks only: the records of one chunk.
  void writeChunk(const uint8_t* records, uint64_t count);
  uint64_t pointsWritten() const;
  void commit();

private:
  struct State;
  std::unique_ptr<State> state_;
};

// Converts a LAS, LAZ or COPC file to LAS or LAZ (by the output's extension) keeping every point record
// byte for byte, the header's fields, the VLRs (extra bytes descriptions included) and the EVLRs, but
// not the LASzip and COPC ones (their offsets would not hold). Waveform formats (4, 5, 9, 10) are
// refused unless dropWaveforms, which writes their records without the packets (formats 1, 3, 6, 8).
// Returns the points written. Throws InputError.
// pointFormat (0-3, 6-8) converts the records to another format (LAS 1.4 for 6-8), refusing with one
// line a record whose attributes the target cannot hold (colors into format 1, channels into 3...).
// How a clip culled the nodes of an octree or COPC input: nodes seen, and skipped without reading their
// points because their cube holds no point the clip keeps.
struct ClipNodeStats {
  uint64_t nodes = 0, skipped = 0;
};
// With a filter, only the records that pass it are written (after `keep`, when set, also accepts them);
// the header's counts and bounds describe what was written. A COPC file's chunks whose cube the clip
// rejects as a whole are not decoded (counted in nodeStats). An empty output path writes nothing: the
// records only go to `keep`.
struct LasConvertOptions {
  int pointFormat = -1;  // -1: the input's (without the waveform packets when they are dropped)
  int versionMinor = -1; // LAS 1.x: -1 the input's (1.4 when the format needs it), 2 or 4; without
                         // pointFormat, 2 picks format 0-3 and 4 format 6-8 by the input's attributes
  bool dropWaveforms = false;
  uint32_t chunkSize = 50000;
  bool progress = false;
  const PointFilter* filter = nullptr; // null or inactive: every record
  std::function<bool(const uint8_t* record, const FilterPoint& point)> keep;
  ClipNodeStats* nodeStats = nullptr;
};
uint64_t convertLasFile(const std::filesystem::path& in, const std::filesystem::path& out,
                        const LasConvertOptions& options = {});

// Exports every point of an octree as LAS (LAZ by the extension) through LasRecordWriter, exactly (the
// source's integers, scale/offset and 16-bit colors): nodes in forEachNode order, decoded on all cores a
// batch at a time, so memory stays a few batches of nodes whatever the octree's size. Returns the points
// written.
// With a filter (the source must hold what it reads: requireFilterAttributes), only the points that pass
// it are written; nodes whose cube the clip rejects as a whole are not read (counted in nodeStats), and
// the points of nodes it accepts as a whole are tested by the attribute filters alone.
uint64_t writeLasFromOctree(const std::filesystem::path& path, lod::NodeSource& source, LasFlavor flavor,
                            bool progress, const PointFilter* filter = nullptr,
                            ClipNodeStats* nodeStats = nullptr);

// Writes RGBA8 pixels (row 0 = top) as an 8-bit RGB PNG (alpha dropped).
void writePng(const std::filesystem::path& path, uint32_t width, uint32_t height, const uint32_t* rgba);
// The same PNG in memory, for a front end that sends it instead of writing it (the browser viewer's
// screenshots). InputError for a size stb cannot encode.
std::vector<uint8_t> encodePng(uint32_t width, uint32_t height, const uint32_t* rgba);

} // namespace pointrast::io

// Reading LAZ files (LASzip-compressed LAS, COPC included): chunks decode in parallel on all cores,
// one chunk per task, and land in file order, so the result is the same on any number of threads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "io/las/laz_chunk.h"
#include "io/point_source.h"
#include "io/reader.h"

namespace pointrast::io {

// Reads a LAZ file into a PointCloud: records decode straight into the cloud's arrays, colors follow
// the LAS rule (16-bit when any value exceeds 255). Throws InputError.
PointCloud readLaz(const std::filesystem::path& path, const ReadOptions& options = {});

// How the chunks of a LAZ read converted their colors: each chunk by its own depth (16-bit when a value of
// the chunk exceeds 255). A file with any 16-bit chunk is 16-bit, and then the chunks converted as 8-bit
// are black (they hold only values <= 255): readLaz() applies the rule to the whole file.
struct LazColorDepths {
  bool any16 = false;                                  // some chunk read was 16-bit
  std::vector<std::pair<uint64_t, uint64_t>> eightBit; // [first, count) runs of the cloud read as 8-bit
};

// Records [firstRecord, firstRecord + recordCount) of a LAZ file (clamped to its points), as readLaz()
// reads the whole file, for a process that draws only its share (docs/mpi.md): only the chunks holding
// them are read and decoded. Bounds are those of the records read. With `depths`, the 8-bit runs are left
// as read and reported, so that processes reading shares can agree on the file's depth (blackenEightBit()
// when any share had a 16-bit chunk); without, the rule is applied to the records read. Throws InputError.
PointCloud readLazRange(const std::filesystem::path& path, const ReadOptions& options, uint64_t firstRecord,
                        uint64_t recordCount, LazColorDepths* depths);

// Makes the runs read as 8-bit black: the file holds a 16-bit chunk somewhere.
void blackenEightBit(PointCloud& cloud, const LazColorDepths& depths);

// Every point record of a LAZ file as the raw bytes an uncompressed LAS file would hold, in file order.
std::vector<uint8_t> readLazRecords(const std::filesystem::path& path, unsigned threads = 0);

// A LAZ file as a PointSource: one piece per chunk.
std::unique_ptr<PointSource> openLazSource(const std::filesystem::path& path);

namespace detail {

FileInfo probeLaz(const std::filesystem::path& path);

// Threads the LAZ reader decodes on (0, the default: all hardware threads). Tests compare 1 and many.
void setLazThreads(unsigned threads);
unsigned lazThreads();

// Decodes chunks [beginChunk, endChunk) of an opened LAZ file (all by default) on `threads` threads in
// windows of a few chunks per thread (memory: the window's records), then hands each window to
// deliver(firstChunk, records) on the calling thread in file order; records[i] holds chunk
// firstChunk + i's raw records. Throws InputError.
using ChunkWindowFn = std::function<void(size_t firstChunk, std::vector<std::vector<uint8_t>>& records)>;
void decodeLazInWindows(const InputFile& file, const laz::LazFile& laz, unsigned threads,
                        const ChunkWindowFn& deliver, size_t beginChunk = 0, size_t endChunk = SIZE_MAX);

// Decoders handed out to the threads of a source (COPC nodes, LAZ pieces): each call takes one or
// makes one, and gives it back after the chunk, so a source keeps as many as threads use it at once.
class ChunkDecoderPool {
public:
  explicit ChunkDecoderPool(laz::Layout layout);
  ~ChunkDecoderPool();
  // Decodes one chunk with a pooled decoder into records (raw).
  void decode(const InputFile& file, const laz::Chunk& chunk, const std::string& what,
              std::vector<uint8_t>& records);

private:
  struct Slot;
  laz::Layout layout_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<Slot>> idle_;
};

} // namespace detail

} // namespace pointrast::io

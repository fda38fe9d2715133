// The octree build's phases on points held in memory, and the parallel chunk pipeline that the
// out-of-core driver (io/potree/lod_builder.h) shares: count -> chunk -> distribute -> index + write.
// No files: the driver reads inputs and spills; these work on records and hand nodes to a NodeSink.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "base/large_buffer.h"
#include "cloud/lod_assemble.h"
#include "cloud/lod_chunks.h"

namespace pointrast::lod {

using Pieces = std::vector<std::vector<PointRecord>>;

struct LodRunOptions {
  unsigned threads = 0;                      // 0: all hardware threads
  const std::atomic<bool>* cancel = nullptr; // set from elsewhere (a signal): the build throws Interrupted
  bool progress = true;                      // progress lines on a terminal
  uint64_t chunkPoints = 0;                  // chunk size limit; 0: chosen from the count and threads
  ChunkIndexer* indexer = nullptr;           // indexes the chunks (the GPU); null: indexChunk on the CPU
};

struct LodPhase {
  std::string name;
  double seconds = 0;       // wall time
  double cpuSeconds = 0;    // CPU time of the process (all threads) meanwhile
  uint64_t points = 0;      // points the phase went through
  uint64_t bytes = 0;       // bytes it read or wrote, where it touches files (0 otherwise)
  bool overlapped = false;  // ran during the phase before it (its time is part of that phase's)
  double threadSeconds = 0; // an overlapped phase on several threads at once: its time summed over them
};

// Times a phase: wall and process CPU time from construction to done().
class PhaseClock {
public:
  PhaseClock();
  LodPhase done(std::string name, uint64_t points, uint64_t bytes = 0) const;

private:
  std::chrono::steady_clock::time_point wall_;
  double cpu_;
};

// Throws Interrupted when options.cancel is set.
void checkCancel(const LodRunOptions& options);

// A named point in a build where it can be held for tests: when the environment's POINTRAST_TEST_HOLD
// names `point` and the build can be cancelled, it waits there until cancelled and throws Interrupted, so
// that a test's signal lands at that point whatever the machine's load. Otherwise it returns at once.
void holdForTest(const char* point, const LodRunOptions& options);

// The quantized extremes of all records.
detail::QuantBox quantBoxOf(const Pieces& pieces, const LodRunOptions& options);

// Phase "count": the histogram of the points over the grid's count-level cells (8^countLevel entries).
std::vector<uint64_t> countPoints(const LodGrid& grid, const Pieces& pieces, const LodRunOptions& options);

// Phase "distribute": every record, with its code, moved into one array grouped by count-level cell,
// cells in Morton order (the order inside a cell is arbitrary: indexing sorts it). Pieces are freed as
// they are moved. refs: each item's ref is its record's place in the pieces, one after another (the
// index of its tail in an in-memory tail store); else 0.
LargeBuffer<LodItem> distributePoints(const LodGrid& grid, const std::vector<uint64_t>& counts,
                                      Pieces& pieces, const LodRunOptions& options, bool refs = false);

// Items of chunk i grouped by count-level cell (indexChunk's input): a view into memory the caller keeps,
// or into storage, which the loader fills; with the tail store their refs index, where points carry tails.
struct ChunkStorage {
  std::vector<LodItem> items;
  std::vector<uint8_t> tails;
};
struct LoadedChunk {
  std::span<LodItem> items;
  const uint8_t* tails = nullptr;
};
using ChunkLoader = std::function<LoadedChunk(size_t chunk, ChunkStorage& storage)>;

struct IndexTimes {
  LodPhase index; // indexing and writing together (they overlap)
  // Time spent handing nodes to the sink, within index.seconds: all of it, summed over the threads
  // (writing runs on several at once), and the part in the builder's order (one thread at a time).
  double writeSeconds = 0;
  double orderSeconds = 0;
};

// Phases "index" and "write": chunks indexed on all threads, each handed to the assembler in chunk order
// as soon as the ones before it are, by whichever thread finished it (one at a time). At most `window`
// chunks are loaded or waiting at once, which bounds memory. Calls assembler.finish().
// counts: the histogram the chunks were planned from.
IndexTimes indexChunks(const std::vector<LodChunk>& chunks, const std::vector<uint64_t>& counts,
                       const ChunkLoader& load, const LodGrid& grid, const LodParams& params,
                       OctreeAssembler& assembler, size_t window, const LodRunOptions& options);

// The "write" phase of indexChunks' times (overlapped with "index"): seconds is the part in the
// builder's order (one thread at a time), threadSeconds all of it summed over the threads.
LodPhase writePhase(const IndexTimes& times, uint64_t points);

// Chunk size for points in memory: small enough for every thread to get several chunks, no smaller than
// a leaf (planChunks' guarantee) and at most 1 M points (a thread's scratch stays ~100 MB).
uint64_t inMemoryChunkLimit(uint64_t points, unsigned threads, uint64_t leafPoints);

struct LodBuildStats {
  AssembleStats octree;
  std::vector<LodPhase> phases;
  uint64_t chunks = 0;
};

// The whole build of points held in memory, from "count" on (the caller has read them, and made the grid
// from their extremes: quantBoxOf + makeLodGrid). Pieces are consumed. tails: with params.tailBytes > 0,
// every record's tail, in the order of the pieces' records one after another.
LodBuildStats buildInMemory(Pieces pieces, const LodGrid& grid, const LodParams& params, NodeSink& sink,
                            const LodRunOptions& options, const uint8_t* tails = nullptr);

} // namespace pointrast::lod

// `pointrast lod`: builds a level-of-detail octree from point files, in memory when the points fit the
// memory bound, out of core with temporary chunk files when not, on all cores, into a NodeSink (a
// PotreeWriter through an adapter, or memory). The algorithm is in src/cloud (lod_*.h); this is the
// driver with files and threads. Phases, each timed:
//   read        in memory: every point read once (all cores), converted to the common frame
//               out of core: one pass for the exact bounds and color depth
//   count       histogram of the points over the cells of the cube (out of core: a second pass)
//   chunk       cells merged into chunks from the histogram
//   distribute  points grouped by chunk: in memory, or into temporary chunk files (a third pass)
//   index       per chunk, on all cores: canonical sort and top-down subsampling with color averages
//   write       nodes handed to the sink in post-order while indexing goes on (overlapped)
// The octree and its bytes depend on the points only: not on the threads, the memory bound or the input
// order of the points.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "cloud/lod_build.h"
#include "cloud/octree.h"
#include "cloud/point_attributes.h"

namespace pointrast::io {

struct LodBuildOptions {
  double spacing = 0;           // root spacing; 0: cube edge / 128 (rounded to edge / 2^k, k in 4..14)
  uint64_t leafPoints = 20'000; // a node whose cube holds more input points is split
  uint64_t memoryBytes = 0;     // bound on the build's memory; 0: defaultBuildMemory()
  unsigned threads = 0;         // 0: all hardware threads
  bool averageColors = true;    // inner nodes' colors: averages of the points they stand for
  bool progress = true;         // progress lines on stderr when it is a terminal
  const std::atomic<bool>* cancel = nullptr; // when set (by a signal handler), the build throws Interrupted
  lod::ChunkIndexer* indexer = nullptr;      // indexes the chunks (the GPU); null: on the CPU
};

// Half of the physical memory, or of the control group's limit where that is lower.
uint64_t defaultBuildMemory();

struct LodBuildReport {
  lod::OctreeMetadata metadata; // as handed to the writer, with depth filled in
  lod::AssembleStats octree;
  std::vector<lod::LodPhase> phases;
  bool outOfCore = false;
  uint64_t chunks = 0;
  uint64_t memoryBytes = 0; // the bound the build ran under
  unsigned threads = 0;
  uint64_t inputBytes = 0; // bytes of point records in the input files (0 where unknown)
  uint64_t spillBytes = 0; // bytes written to temporary chunk files
  uint32_t tailBytes = 0;  // bytes of each point's attribute tail (OctreeBuilder::tail())
  double seconds = 0;      // from the first read to the last node
};

class OctreeBuilder {
public:
  // Opens the inputs (headers only) and chooses their common frame. Throws InputError.
  OctreeBuilder(const std::vector<std::filesystem::path>& inputs, const LodBuildOptions& options);
  ~OctreeBuilder();
  OctreeBuilder(const OctreeBuilder&) = delete;
  OctreeBuilder& operator=(const OctreeBuilder&) = delete;

  uint64_t points() const;
  // Whether the points fit the memory bound (decided from the headers' counts).
  bool inMemory() const;

  // Phase "read": what an octree writer needs before the first node (cube, spacing, frame, fields, count).
  const lod::OctreeMetadata& scan();
  // The attributes every point carries beside its record (cloud/point_attributes.h), handed to the sink
  // with the records.
  const TailFormat& tail() const;
  // The other phases, into sink. Out of core, temporary files go into tempDir, which must not exist yet
  // and is removed before returning (also when an exception leaves).
  LodBuildReport build(lod::NodeSink& sink, const std::filesystem::path& tempDir);

private:
  struct State;
  std::unique_ptr<State> state_;
};

} // namespace pointrast::io

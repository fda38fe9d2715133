// The octree builder's index phase on the GPU (cloud/lod_index.h has the rules it keeps): each chunk's
// points sorted by Morton code with a radix sort, then every level's subsample chosen in parallel over
// the points (each adds its distance and color to its grid cell with atomics; the cell's first point
// marks the choice). The CPU puts equal codes into their canonical order between the two and lays out
// the nodes from the levels the points were taken at, so the octree is the one indexChunk makes, byte for
// byte.
//
// Three chunks are in flight at a time, each with buffers of its own (a slot), so that chunks' host
// copies and equal-code ordering run while another's submission runs; submissions go to the device one
// at a time. The other indexing threads lay out their nodes, encode and write meanwhile. Chunks the GPU path
// does not cover are indexed on the CPU: a grid with unequal scales on its axes (its distances are weighted
// in double), chunks of more than 2^32 - 1 points, and chunks whose buffers the device cannot hold.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "cloud/lod_index.h"
#include "gpu/buffer.h"
#include "gpu/program.h"

namespace pointrast::gpu {
class Context;
}

namespace pointrast::render {

class GpuIndexer : public lod::ChunkIndexer {
public:
  explicit GpuIndexer(gpu::Context& context);
  ~GpuIndexer() override;

  void index(lod::ChunkNodes& out, lod::IndexScratch& scratch, const lod::LodGrid& grid,
             const lod::NodeKey& chunk, lod::LodItem* items, size_t count, const uint64_t* cellCounts,
             size_t cells, const lod::LodParams& params, const uint8_t* tails) override;

  struct Stats {
    uint64_t gpuChunks = 0, cpuChunks = 0; // chunks indexed on each
    uint64_t gpuPoints = 0, cpuPoints = 0;
    double deviceSeconds = 0; // wall time of the device's work (submissions and transfers), summed
    // deviceSeconds in its steps: the items into staging; the sort's submission (upload, radix passes,
    // gather, the sorted points down) and their copy out; the equal-code pass where codes repeat; the
    // levels' submission; the levels and colors out of staging.
    double stageSeconds = 0, sortSeconds = 0, orderSeconds = 0, levelSeconds = 0, readSeconds = 0;
    double waitSeconds = 0; // the indexing threads' time waiting for a free slot, summed
    // The submissions from start to finish, summed: they run one at a time, so the device's busy time.
    double busySeconds = 0;

    Stats& operator+=(const Stats& o) {
      gpuChunks += o.gpuChunks;
      cpuChunks += o.cpuChunks;
      gpuPoints += o.gpuPoints;
      cpuPoints += o.cpuPoints;
      deviceSeconds += o.deviceSeconds;
      stageSeconds += o.stageSeconds;
      sortSeconds += o.sortSeconds;
      orderSeconds += o.orderSeconds;
      levelSeconds += o.levelSeconds;
      readSeconds += o.readSeconds;
      waitSeconds += o.waitSeconds;
      busySeconds += o.busySeconds;
      return *this;
    }
  };
  Stats stats() const;

private:
  struct Slot;
  static constexpr size_t kSlots = 3;

  // Sorts and subsamples on the device; false when its buffers cannot be had (the CPU takes the chunk).
  bool indexOnDevice(const lod::LodGrid& grid, const lod::NodeKey& chunk, lod::LodItem* items, size_t count,
                     const lod::LodParams& params, uint32_t* levels, uint32_t* colors);
  Slot& acquire(); // waits for a free slot
  void release(Slot& slot);
  void submit(const std::function<void(VkCommandBuffer)>& record); // one at a time, waits for it

  gpu::Context& context_;
  gpu::ComputeProgram histogram_, scan_, scatter_, gather_, cells_, best_, level_;
  std::mutex deviceMutex_;   // one submission at a time: the context's queue and command pool
  mutable std::mutex mutex_; // guards free_ and stats_
  std::condition_variable freed_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<Slot*> free_;
  Stats stats_;
};

} // namespace pointrast::render

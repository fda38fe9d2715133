// The octree builder's index phase on the GPU (render/gpu_indexer.h) against the CPU's: the same nodes,
// records and tails, byte for byte, on terrain with many chunks and levels, on copies of one point (equal
// codes down to the deepest level), on cells crowded with colored points (color averages), with and
// without color filtering, on several threads; and grids the GPU path leaves to the CPU.
#include <random>

#include "cloud/generate.h"
#include "cloud/lod_test_util.h"
#include "gpu/gpu_fixture.h"
#include "render/gpu_indexer.h"

namespace {

using namespace pointrast;
using namespace pointrast::lodtest;

// MemorySink's hash over the nodes and their records, and over the tails as well.
class TailSink : public MemorySink {
public:
  explicit TailSink(uint32_t tailBytes) : tailBytes_(tailBytes) {}
  void writeNode(const lod::NodeKey& key, const PointRecord* records, const uint8_t* tails,
                 size_t count) override {
    MemorySink::writeNode(key, records, tails, count);
    for (size_t i = 0; i < count * tailBytes_; ++i)
      tailHash = (tailHash ^ tails[i]) * 0x100000001b3ull;
  }
  uint64_t tailHash = 0xcbf29ce484222325ull;

private:
  uint32_t tailBytes_;
};

struct Result {
  uint64_t hash = 0, tailHash = 0;
  size_t nodes = 0;
};

Result buildWith(lod::ChunkIndexer* indexer, const std::vector<PointRecord>& records,
                 const lod::LodGrid& grid, const lod::LodParams& params, unsigned threads,
                 uint64_t chunkPoints, const std::vector<uint8_t>& tails = {}) {
  TailSink sink(params.tailBytes);
  lod::LodRunOptions options;
  options.threads = threads;
  options.progress = false;
  options.chunkPoints = chunkPoints;
  options.indexer = indexer;
  lod::buildInMemory(piecesOf(records, 7'000), grid, params, sink, options,
                     tails.empty() ? nullptr : tails.data());
  expectValidOctree(sink.nodes, records, grid, params);
  return {sink.hash, sink.tailHash, sink.nodes.size()};
}

class GpuIndexTest : public test::GpuTest {
protected:
  // Builds on the CPU and on the GPU; expects the same bytes, and that the GPU indexed `gpuChunks`.
  void expectSameOctree(const std::vector<PointRecord>& records, const lod::LodGrid& grid,
                        const lod::LodParams& params, unsigned threads, uint64_t chunkPoints,
                        bool onGpu = true, const std::vector<uint8_t>& tails = {}) {
    const Result cpu = buildWith(nullptr, records, grid, params, threads, chunkPoints, tails);
    render::GpuIndexer indexer(*context);
    const Result gpu = buildWith(&indexer, records, grid, params, threads, chunkPoints, tails);
    EXPECT_EQ(gpu.nodes, cpu.nodes);
    EXPECT_EQ(gpu.hash, cpu.hash);
    EXPECT_EQ(gpu.tailHash, cpu.tailHash);
    const render::GpuIndexer::Stats stats = indexer.stats();
    if (onGpu) {
      EXPECT_GT(stats.gpuChunks, 0u);
      EXPECT_EQ(stats.cpuChunks, 0u);
      EXPECT_EQ(stats.gpuPoints, records.size());
    } else {
      EXPECT_EQ(stats.gpuChunks, 0u);
      EXPECT_EQ(stats.cpuPoints, records.size());
    }
  }
};

TEST_F(GpuIndexTest, TerrainOnManyChunksAndThreads) {
  const std::vector<PointRecord> records = terrainRecords(40'000, 9);
  const lod::LodGrid grid = gridOf(records);
  for (bool average : {true, false}) {
    lod::LodParams params;
    params.leafPoints = 500;
    params.averageColors = average;
    expectSameOctree(records, grid, params, 3, 4'000);
  }
  // One chunk for everything: the whole tree from the root in one pass of the levels.
  lod::LodParams params;
  params.leafPoints = 2'000;
  expectSameOctree(records, grid, params, 1, 1'000'000);
}

// Equal codes whose records differ: their order comes from the bytes (the CPU puts the GPU's sorted runs
// of equal codes in order), and the subsample's tie goes to the first of them.
TEST_F(GpuIndexTest, CopiesOfPointsDownToTheDeepestLevel) {
  std::vector<PointRecord> records(3'000);
  std::mt19937_64 rng(4);
  for (size_t i = 0; i < records.size(); ++i) {
    records[i].x = 1000 + int(i % 2);
    records[i].intensity = uint16_t(rng() % 5);
    records[i].rgb[0] = uint16_t(rng());
  }
  records.push_back(PointRecord{});
  records.back().y = 4000;
  std::shuffle(records.begin(), records.end(), rng);
  const lod::LodGrid grid = gridOf(records);
  lod::LodParams params;
  params.leafPoints = 50;
  expectSameOctree(records, grid, params, 2, 100);
}

// A lattice on a coarse grid (4 cells per node edge): cells hold many points, colors average over them;
// with tails (the attributes beyond the record) carried beside the points.
TEST_F(GpuIndexTest, CrowdedCellsAverageColorsAndCarryTails) {
  const std::vector<PointRecord> records = latticeRecords(30);
  const lod::LodGrid grid = gridOf(records, glm::dvec3(0.01), glm::dvec3(100, 200, 0), 2);
  for (bool average : {true, false}) {
    lod::LodParams params;
    params.leafPoints = 40;
    params.averageColors = average;
    expectSameOctree(records, grid, params, 2, 300);
  }
  lod::LodParams params;
  params.leafPoints = 40;
  params.tailBytes = 3;
  std::vector<uint8_t> tails(records.size() * params.tailBytes);
  for (size_t i = 0; i < tails.size(); ++i)
    tails[i] = uint8_t(i * 7 + i / 3);
  expectSameOctree(records, grid, params, 2, 300, true, tails);
}

// Unequal scales weigh distances in double: those grids are indexed on the CPU, with the same result.
TEST_F(GpuIndexTest, UnequalScalesStayOnTheCpu) {
  const std::vector<PointRecord> records = terrainRecords(5'000, 9);
  const lod::LodGrid grid = gridOf(records, glm::dvec3(0.01, 0.01, 0.001));
  ASSERT_FALSE(grid.isotropic);
  lod::LodParams params;
  params.leafPoints = 500;
  expectSameOctree(records, grid, params, 2, 1'000, false);
}

} // namespace

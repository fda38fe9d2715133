// The octree builder's core on points in memory: frame and codes, chunk planning, and built octrees
// checked against their input (every point once, exact; cubes, leaf limit, one point per grid cell, color
// averages), the same nodes and bytes whatever the threads, chunks, pieces and input order.
#include <random>

#include "cloud/lod_chunks.h"
#include "cloud/lod_test_util.h"

namespace {

using namespace pointrast;
using namespace pointrast::lodtest;
using lod::NodeKey;

TEST(LodGrid, CubeHoldsEveryPointAndCodesNestLevels) {
  std::vector<PointRecord> records = terrainRecords(20'000);
  lod::LodGrid grid = gridOf(records);
  const double edge = grid.cube.max.x - grid.cube.min.x;
  EXPECT_DOUBLE_EQ(grid.cube.max.y - grid.cube.min.y, edge);
  EXPECT_DOUBLE_EQ(grid.spacing(), edge / 128);
  for (const PointRecord& r : records) {
    const uint64_t code = grid.code(r);
    ASSERT_LT(code, uint64_t(1) << 63);
    ASSERT_EQ(grid.countCell(r), code >> 3 * (lod::kCodeLevels - grid.countLevel()));
    uint32_t cells[3];
    grid.codeCells(r, cells);
    ASSERT_EQ(code, detail::spreadBits3(cells[0]) << 2 | detail::spreadBits3(cells[1]) << 1 |
                        detail::spreadBits3(cells[2]));
    for (int level = 0; level <= lod::kCodeLevels; ++level) {
      const NodeKey key = lod::keyOfCode(code, level);
      ASSERT_EQ(lod::cellOfKey(key), code >> 3 * (lod::kCodeLevels - level));
      if (level > 0) {
        ASSERT_EQ(key.parent(), lod::keyOfCode(code, level - 1));
        ASSERT_EQ(key.parent().child(key.childIndex()), key);
      }
    }
  }
}

TEST(LodGrid, ExtremesLandInsideTheCube) {
  std::vector<PointRecord> records(2);
  records[0].x = -2'000'000'000;
  records[0].y = 5;
  records[1].x = 2'000'000'000;
  records[1].z = 7;
  lod::LodGrid grid = gridOf(records, glm::dvec3(1.0));
  EXPECT_EQ(grid.code(records[0]) >> 60, 0u);
  // The largest x maps to the last cell of the x axis, not past it.
  EXPECT_EQ(detail::compactBits3(grid.code(records[1]) >> 2), (1u << 21) - 1);
  EXPECT_EQ(lod::gridLevelsForSpacing(1024, 8), 7);
  EXPECT_EQ(lod::gridLevelsForSpacing(1024, 0), lod::kDefaultGridLevels);
  EXPECT_EQ(lod::gridLevelsForSpacing(1024, 1e-9), 14);
}

TEST(LodIndex, SortItemsGivesTheCanonicalOrder) {
  std::mt19937_64 rng(9);
  for (size_t n : {0, 1, 2, 23, 24, 25, 100, 5'000, 70'000}) {
    std::vector<lod::LodItem> items(n);
    for (auto& item : items) {
      // Codes sharing their top 21 bits, few distinct low parts: many ties for the record bytes to break.
      item.code = (uint64_t(12345) << 42) | (rng() % (n / 4 + 1)) << (rng() % 3 == 0 ? 20 : 0);
      item.record.x = int32_t(rng() % 3);
      item.record.intensity = uint16_t(rng() % 2);
    }
    std::vector<lod::LodItem> expected = items;
    std::sort(expected.begin(), expected.end(), [](const lod::LodItem& a, const lod::LodItem& b) {
      if (a.code != b.code) return a.code < b.code;
      return std::memcmp(&a.record, &b.record, sizeof(PointRecord)) < 0;
    });
    lod::IndexScratch scratch;
    lod::sortItems(items.data(), items.size(), 42, scratch);
    for (size_t i = 0; i < n; ++i) {
      ASSERT_EQ(items[i].code, expected[i].code) << n << " " << i;
      ASSERT_EQ(std::memcmp(&items[i].record, &expected[i].record, sizeof(PointRecord)), 0) << n << " " << i;
    }
  }
}

TEST(LodChunks, LargestCellsUnderTheLimitInMortonOrder) {
  const int level = 2; // 64 cells
  std::vector<uint64_t> counts(64, 0);
  counts[0] = 5;
  counts[1] = 5;  // cell 0 of level 1 holds 10
  counts[8] = 30; // cell 1 of level 1 holds 31: split
  counts[9] = 1;
  counts[63] = 50; // a single cell over the limit is a chunk anyway
  std::vector<lod::LodChunk> chunks = lod::planChunks(counts, level, 20);
  ASSERT_EQ(chunks.size(), 4u);
  EXPECT_EQ(chunks[0].key, (NodeKey{1, 0, 0, 0}));
  EXPECT_EQ(chunks[0].points, 10u);
  EXPECT_EQ(chunks[1].key, lod::keyOfCode(uint64_t(8) << 57, 2));
  EXPECT_EQ(chunks[1].points, 30u);
  EXPECT_EQ(chunks[2].key, lod::keyOfCode(uint64_t(9) << 57, 2));
  EXPECT_EQ(chunks[3].key, lod::keyOfCode(uint64_t(63) << 57, 2));
  EXPECT_EQ(chunks[3].points, 50u);
  std::vector<uint32_t> table = lod::chunkOfCell(chunks, level);
  EXPECT_EQ(table[1], 0u);
  EXPECT_EQ(table[7], 0u);
  EXPECT_EQ(table[9], 2u);
  EXPECT_EQ(table[10], UINT32_MAX);
  // Everything in one chunk when the limit allows.
  EXPECT_EQ(lod::planChunks(counts, level, 1000).size(), 1u);
}

TEST(LodBuild, TerrainOctreeHoldsEveryPointOnce) {
  std::vector<PointRecord> records = terrainRecords(200'000);
  lod::LodGrid grid = gridOf(records);
  for (bool average : {true, false}) {
    lod::LodParams params;
    params.leafPoints = 3'000;
    params.averageColors = average;
    Built built = build(records, grid, params, 2, 20'000);
    expectValidOctree(built.sink.nodes, records, grid, params);
    EXPECT_EQ(built.stats.octree.points, records.size());
    EXPECT_EQ(built.stats.octree.nodes, built.sink.nodes.size());
    EXPECT_GE(built.stats.octree.levels, 3);
    EXPECT_GT(built.stats.chunks, 4u);
  }
}

TEST(LodBuild, SameBytesWhateverThreadsChunksPiecesAndInputOrder) {
  std::vector<PointRecord> records = terrainRecords(120'000);
  lod::LodGrid grid = gridOf(records);
  lod::LodParams params;
  params.leafPoints = 2'000;
  const Built reference = build(records, grid, params, 1, 0);
  expectValidOctree(reference.sink.nodes, records, grid, params);
  EXPECT_EQ(build(records, grid, params, 2, 0).sink.hash, reference.sink.hash);
  EXPECT_EQ(build(records, grid, params, 3, 2'000, 777).sink.hash, reference.sink.hash);
  EXPECT_EQ(build(records, grid, params, 2, 1'000'000).sink.hash, reference.sink.hash);
  std::vector<PointRecord> shuffled = records;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(11));
  const Built fromShuffled = build(shuffled, grid, params, 2, 5'000, 10'000);
  EXPECT_EQ(fromShuffled.sink.hash, reference.sink.hash);
  EXPECT_GT(fromShuffled.stats.chunks, 10u);
}

// A lattice with random colors on a coarse grid (4 cells per node edge), so cells hold many points.
TEST(LodBuild, InnerColorsAreTheAveragesOfThePointsTheyStandFor) {
  const std::vector<PointRecord> records = latticeRecords(40);
  // Equal scales (integer distances) and a finer z scale (weighted distances).
  for (glm::dvec3 scale : {glm::dvec3(0.01), glm::dvec3(0.01, 0.01, 0.001)}) {
    lod::LodGrid grid = gridOf(records, scale, glm::dvec3(100, 200, 0), 2);
    EXPECT_EQ(grid.isotropic, scale.z == scale.x);
    for (bool average : {true, false}) {
      lod::LodParams params;
      params.leafPoints = 60;
      params.averageColors = average;
      Built built = build(records, grid, params, 2, 300);
      expectValidOctree(built.sink.nodes, records, grid, params);
      expectFilteredColors(built.sink.nodes, records, grid, params);
    }
  }
}

TEST(LodBuild, CopiesOfOnePointEndInTheDeepestNode) {
  std::vector<PointRecord> records(5'000);
  for (size_t i = 0; i < records.size(); ++i) {
    records[i].x = 1000;
    records[i].intensity = uint16_t(i % 3); // three distinct records, many copies of each
  }
  records.push_back(PointRecord{});
  records.back().x = 0;
  records.back().y = 4000;
  lod::LodGrid grid = gridOf(records);
  lod::LodParams params;
  params.leafPoints = 100;
  Built built = build(records, grid, params, 2, 100);
  expectValidOctree(built.sink.nodes, records, grid, params);
  EXPECT_EQ(built.stats.octree.levels, lod::kMaxLevel + 1);
  // Records with equal codes are ordered by their bytes, not by where they came from.
  for (uint64_t seed : {1, 2, 3}) {
    std::vector<PointRecord> shuffled = records;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(seed));
    EXPECT_EQ(build(shuffled, grid, params, 2, 100, 333).sink.hash, built.sink.hash);
  }
}

TEST(LodBuild, FewPointsMakeOneLeaf) {
  std::vector<PointRecord> records = terrainRecords(500);
  lod::LodGrid grid = gridOf(records);
  Built built = build(records, grid, lod::LodParams{});
  ASSERT_EQ(built.sink.nodes.size(), 1u);
  EXPECT_EQ(built.sink.nodes[0].key, NodeKey{});
  expectValidOctree(built.sink.nodes, records, grid, lod::LodParams{});
  std::vector<PointRecord> one(1);
  Built single = build(one, gridOf(one), lod::LodParams{});
  ASSERT_EQ(single.sink.nodes.size(), 1u);
  EXPECT_EQ(single.sink.nodes[0].records.size(), 1u);
}

TEST(LodBuild, FinerAndCoarserGrids) {
  std::vector<PointRecord> records = terrainRecords(60'000);
  for (int levels : {4, 5, 9}) {
    lod::LodGrid grid = gridOf(records, glm::dvec3(0.001), glm::dvec3(0), levels);
    lod::LodParams params;
    params.leafPoints = 1'500;
    Built built = build(records, grid, params, 2, 4'000);
    expectValidOctree(built.sink.nodes, records, grid, params);
    EXPECT_EQ(build(records, grid, params, 1, 0).sink.hash, built.sink.hash) << levels;
  }
}

} // namespace

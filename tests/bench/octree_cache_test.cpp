// The bench's octree cache without a GPU: an octree built from points in memory holds every point exactly
// once (read back through the Potree reader), the cache builds an entry once and reuses it without asking
// for the points, and a damaged entry is built again with one note.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "bench/octree_cache.h"
#include "cloud/generate.h"
#include "cloud/point_record.h"
#include "io/potree/potree.h"

namespace {

using namespace pointrast;
namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("pointrast-octree-cache-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

PointCloud terrain(uint64_t points) {
  GenerateOptions options;
  options.points = points;
  options.progress = false;
  return generateScene(Scene::Terrain, options);
}

auto recordKey(const PointRecord& r) {
  return std::tie(r.x, r.y, r.z, r.rgb[0], r.rgb[1], r.rgb[2]);
}

std::vector<PointRecord> sorted(std::vector<PointRecord> records) {
  std::sort(records.begin(), records.end(),
            [](const PointRecord& a, const PointRecord& b) { return recordKey(a) < recordKey(b); });
  return records;
}

TEST(OctreeCache, ABuildFromPointsInMemoryHoldsEveryPointOnce) {
  const PointCloud cloud = terrain(70'000);
  const fs::path dir = scratch("build") / "octree";
  const bench::DatasetOctree o = bench::buildCloudOctree(cloud, dir, 2, false);
  EXPECT_EQ(o.path, dir);
  EXPECT_EQ(o.points, 70'000u);
  EXPECT_GT(o.buildSeconds, 0);
  EXPECT_EQ(o.phases.rfind("records ", 0), 0u) << o.phases;
  EXPECT_NE(o.phases.find("index "), std::string::npos) << o.phases;
  EXPECT_NE(o.phases.find("commit "), std::string::npos) << o.phases;
  uint64_t bytes = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    bytes += entry.file_size();
  EXPECT_EQ(o.bytes, bytes);
  for (const auto& entry : fs::directory_iterator(dir.parent_path()))
    EXPECT_EQ(entry.path(), dir) << "no temporary folder left";

  const auto source = io::openPotree(dir);
  const lod::OctreeMetadata& meta = source->metadata();
  EXPECT_EQ(meta.pointCount, 70'000u);
  EXPECT_TRUE(meta.fields.color);
  EXPECT_EQ(meta.scale, cloud.scale);
  EXPECT_EQ(meta.offset, cloud.offset);
  std::vector<PointRecord> read;
  int nodes = 0;
  lod::forEachNode(*source, [&](const lod::NodeInfo& node) {
    const std::vector<PointRecord> records = source->readNode(node);
    read.insert(read.end(), records.begin(), records.end());
    ++nodes;
    return true;
  });
  EXPECT_GT(nodes, 1) << "70 k points are more than a leaf holds";
  std::vector<PointRecord> expected(cloud.size());
  loadRecords(cloud, 0, cloud.size(), expected.data());
  // Positions are kept exactly; inner nodes' colors are averages of their subtree's, so compare positions.
  read = sorted(read);
  expected = sorted(expected);
  ASSERT_EQ(read.size(), expected.size());
  for (size_t i = 0; i < read.size(); ++i)
    ASSERT_TRUE(read[i].x == expected[i].x && read[i].y == expected[i].y && read[i].z == expected[i].z) << i;
  fs::remove_all(dir.parent_path().parent_path());
}

TEST(OctreeCache, BuildsOnceReusesWithoutThePointsAndRebuildsADamagedEntry) {
  const fs::path dir = scratch("cache");
  std::vector<std::string> notes;
  bench::OctreeCacheOptions options;
  options.dir = dir / "octrees"; // created by the first request
  options.threads = 2;
  options.progress = false;
  options.onNote = [&](const std::string& line) { notes.push_back(line); };
  bench::OctreeProvider provider = bench::octreeCache(options);
  const PointCloud cloud = terrain(30'000);
  int asked = 0;
  auto points = [&]() -> const PointCloud& {
    ++asked;
    return cloud;
  };
  const bench::DatasetOctree built = provider("t-30000-seed1", points);
  EXPECT_EQ(asked, 1);
  EXPECT_FALSE(built.reused);
  EXPECT_EQ(built.path, dir / "octrees" / "t-30000-seed1");
  EXPECT_TRUE(fs::exists(dir / "octrees" / "t-30000-seed1.json"));

  const bench::DatasetOctree again = provider("t-30000-seed1", points);
  EXPECT_EQ(asked, 1) << "a cached octree needs no points";
  EXPECT_TRUE(again.reused);
  EXPECT_EQ(again.points, 30'000u);
  EXPECT_EQ(again.buildSeconds, built.buildSeconds);
  EXPECT_EQ(again.phases, built.phases);
  EXPECT_EQ(again.bytes, built.bytes);

  // Another key is another octree; a record that is not JSON marks the entry as damaged.
  provider("t-30000-seed2", points);
  EXPECT_EQ(asked, 2);
  std::ofstream(dir / "octrees" / "t-30000-seed1.json") << "{ not json";
  notes.clear();
  const bench::DatasetOctree rebuilt = provider("t-30000-seed1", points);
  EXPECT_EQ(asked, 3);
  EXPECT_FALSE(rebuilt.reused);
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(
      notes[0].find("is damaged (its build record t-30000-seed1.json is unreadable); building it again"),
      std::string::npos)
      << notes[0];
  // A record of another octree (copied over) is refused too.
  fs::copy_file(dir / "octrees" / "t-30000-seed2.json", dir / "octrees" / "t-30000-seed1.json",
                fs::copy_options::overwrite_existing);
  notes.clear();
  provider("t-30000-seed1", points);
  EXPECT_EQ(asked, 4);
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes[0].find("its build record names another octree"), std::string::npos) << notes[0];
  EXPECT_TRUE(provider("t-30000-seed1", points).reused);
  fs::remove_all(dir.parent_path());
}

TEST(OctreeCache, RecordsRoundTripThroughACloud) {
  PointCloud cloud = terrain(1'000);
  cloud.intensity.assign(cloud.size(), 7);
  std::vector<PointRecord> records(cloud.size());
  loadRecords(cloud, 0, cloud.size(), records.data());
  const RecordFields fields = recordFieldsOf(cloud);
  EXPECT_TRUE(fields.color && fields.intensity && !fields.classification);
  EXPECT_EQ(fields.colorMax, 255);
  PointCloud back;
  appendRecords(back, records.data(), records.size(), fields, 0);
  EXPECT_EQ(back.positions, cloud.positions);
  EXPECT_EQ(back.colors, cloud.colors);
  EXPECT_EQ(back.intensity, cloud.intensity);
}

} // namespace

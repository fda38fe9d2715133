// The octree build driver on files: LAS in, nodes into memory. The same octree and bytes in memory and out
// of core (a memory bound far below the input), from 1 and 2 threads; every input point in exactly one
// node with its integers and attributes; several files merged into one octree; nothing left behind.
#include <random>

#include "cloud/lod_test_util.h"
#include "io/io_test_util.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/point_source.h"
#include "io/potree/lod_builder.h"
#include "io/writer.h"

namespace {

using namespace pointrast;
using namespace pointrast::lodtest;
using iotest::data;

std::vector<PointRecord> readRecords(const std::filesystem::path& path) {
  std::unique_ptr<io::PointSource> source = io::openPointSource(path);
  std::vector<PointRecord> all, piece;
  for (size_t i = 0; i < source->pieces().size(); ++i) {
    source->readPiece(i, piece);
    all.insert(all.end(), piece.begin(), piece.end());
  }
  return all;
}

struct Result {
  MemorySink sink;
  io::LodBuildReport report;
};

Result buildFiles(const std::vector<std::filesystem::path>& inputs, io::LodBuildOptions options,
                  const std::filesystem::path& temp) {
  options.progress = false;
  Result r;
  io::OctreeBuilder builder(inputs, options);
  const lod::OctreeMetadata meta = builder.scan();
  r.report = builder.build(r.sink, temp);
  EXPECT_FALSE(std::filesystem::exists(temp)) << "temporary files left behind";
  EXPECT_EQ(r.report.metadata.cube.min, meta.cube.min);
  EXPECT_EQ(r.report.octree.points, meta.pointCount);
  return r;
}

// The grid the builder must have used: the points' extremes in the file's frame.
lod::LodGrid gridOfFile(const std::vector<PointRecord>& records, const io::LodBuildReport& report) {
  lod::LodGrid grid = gridOf(records, report.metadata.scale, report.metadata.offset);
  EXPECT_EQ(grid.cube.min, report.metadata.cube.min);
  EXPECT_EQ(grid.cube.max, report.metadata.cube.max);
  EXPECT_DOUBLE_EQ(grid.spacing(), report.metadata.spacing);
  return grid;
}

TEST(LodBuilder, AutzenInMemoryAndOutOfCoreGiveTheSameBytes) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  const std::filesystem::path input = data("las/autzen_trim.las");
  const std::vector<PointRecord> records = readRecords(input);
  io::LodBuildOptions options;
  options.leafPoints = 5'000;
  options.threads = 1;
  Result one = buildFiles({input}, options, dir / "t1");
  EXPECT_FALSE(one.report.outOfCore);
  const lod::LodGrid grid = gridOfFile(records, one.report);
  lod::LodParams params;
  params.leafPoints = options.leafPoints;
  expectValidOctree(one.sink.nodes, records, grid, params);
  EXPECT_EQ(one.report.metadata.pointCount, 110'000u);
  EXPECT_TRUE(one.report.metadata.fields.color);
  EXPECT_EQ(one.report.metadata.fields.colorMax, 236);
  EXPECT_EQ(one.report.metadata.depth, one.report.octree.levels - 1);

  options.threads = 2;
  Result two = buildFiles({input}, options, dir / "t2");
  EXPECT_EQ(two.sink.hash, one.sink.hash);

  options.memoryBytes = 1 << 20; // 1 MiB for 2.6 MB of records
  Result spilled = buildFiles({input}, options, dir / "t3");
  EXPECT_TRUE(spilled.report.outOfCore);
  EXPECT_GT(spilled.report.chunks, 2u);
  // A point spills as its record, and with attributes its place in the input and its tail.
  EXPECT_GT(spilled.report.tailBytes, 0u); // autzen's GPS times
  EXPECT_EQ(spilled.report.spillBytes, records.size() * (sizeof(PointRecord) + 8 + spilled.report.tailBytes));
  EXPECT_EQ(spilled.sink.hash, one.sink.hash);
  std::vector<std::string> phases;
  for (const auto& p : spilled.report.phases)
    phases.push_back(p.name);
  EXPECT_EQ(phases, (std::vector<std::string>{"read", "count", "chunk", "distribute", "index", "write"}));

  options.threads = 1;
  EXPECT_EQ(buildFiles({input}, options, dir / "t4").sink.hash, one.sink.hash);
}

TEST(LodBuilder, GeneratedTerrainOutOfCoreEqualsInMemory) {
  iotest::TempDir dir;
  GenerateOptions g;
  g.points = 300'000;
  g.progress = false;
  io::writeLas(dir / "t.las", generateScene(Scene::Terrain, g), io::LasFlavor::Las12Pf2);
  const std::vector<PointRecord> records = readRecords(dir / "t.las");
  io::LodBuildOptions options;
  options.leafPoints = 4'000;
  Result inMemory = buildFiles({dir / "t.las"}, options, dir / "a");
  lod::LodParams params;
  params.leafPoints = options.leafPoints;
  expectValidOctree(inMemory.sink.nodes, records, gridOfFile(records, inMemory.report), params);
  options.memoryBytes = 3 << 20;
  Result spilled = buildFiles({dir / "t.las"}, options, dir / "b");
  EXPECT_TRUE(spilled.report.outOfCore);
  EXPECT_EQ(spilled.sink.hash, inMemory.sink.hash);
}

// Writes records [first, first + count) of a LAS 1.2 file as a file of their own (same header).
void writePart(const std::filesystem::path& from, const std::filesystem::path& to, uint64_t first,
               uint64_t count, double scale = 0) {
  std::vector<uint8_t> bytes = iotest::readBytes(from);
  io::detail::InputFile file(from);
  const io::detail::LasHeader hd = io::detail::readLasHeader(file);
  std::vector<uint8_t> out(bytes.begin(), bytes.begin() + hd.pointOffset);
  out.insert(out.end(), bytes.begin() + ptrdiff_t(hd.pointOffset + first * hd.recordLength),
             bytes.begin() + ptrdiff_t(hd.pointOffset + (first + count) * hd.recordLength));
  io::detail::storeLE<uint32_t>(&out[io::detail::las::kLegacyCount], static_cast<uint32_t>(count));
  if (scale > 0)
    for (int a = 0; a < 3; ++a)
      io::detail::storeLE<double>(&out[io::detail::las::kScale + 8 * a], scale);
  iotest::writeBytes(to, out);
}

TEST(LodBuilder, FilesMergeIntoOneOctree) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  const std::filesystem::path input = data("las/autzen_trim.las");
  writePart(input, dir / "a.las", 0, 60'000);
  writePart(input, dir / "b.las", 60'000, 50'000);
  io::LodBuildOptions options;
  options.leafPoints = 5'000;
  const Result whole = buildFiles({input}, options, dir / "t1");
  // The same points in two files with the same frame: the same octree, byte for byte.
  EXPECT_EQ(buildFiles({dir / "a.las", dir / "b.las"}, options, dir / "t2").sink.hash, whole.sink.hash);
  EXPECT_EQ(buildFiles({dir / "b.las", dir / "a.las"}, options, dir / "t3").sink.hash, whole.sink.hash);
  options.memoryBytes = 1 << 20;
  EXPECT_EQ(buildFiles({dir / "b.las", dir / "a.las"}, options, dir / "t4").sink.hash, whole.sink.hash);
}

TEST(LodBuilder, DifferentScalesMergeOnTheFinerOne) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  const std::filesystem::path input = data("las/autzen_trim.las");
  writePart(input, dir / "a.las", 0, 20'000, 0.02); // autzen's scale is 0.01: these points move
  writePart(input, dir / "b.las", 20'000, 20'000);
  io::LodBuildOptions options;
  options.leafPoints = 3'000;
  const Result r = buildFiles({dir / "a.las", dir / "b.las"}, options, dir / "t");
  EXPECT_EQ(r.report.metadata.scale, glm::dvec3(0.01));
  // Every point keeps its world position exactly: 0.02 is a multiple of 0.01.
  std::vector<glm::dvec3> expected, got;
  for (const auto& [path, scale] : {std::pair{dir / "a.las", 0.02}, std::pair{dir / "b.las", 0.01}}) {
    io::detail::InputFile file(path);
    const glm::dvec3 offset = io::detail::readLasHeader(file).offset;
    for (const PointRecord& q : readRecords(path))
      expected.push_back(glm::dvec3(q.x, q.y, q.z) * scale + offset);
  }
  for (const WrittenNode& node : r.sink.nodes)
    for (const PointRecord& q : node.records)
      got.push_back(glm::dvec3(q.x, q.y, q.z) * r.report.metadata.scale + r.report.metadata.offset);
  auto less = [](const glm::dvec3& a, const glm::dvec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  };
  std::sort(expected.begin(), expected.end(), less);
  std::sort(got.begin(), got.end(), less);
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i)
    ASSERT_NEAR(glm::length(got[i] - expected[i]), 0.0, 1e-6) << i;
}

TEST(LodBuilder, EightAndSixteenBitColorsMergeAtSixteenBits) {
  POINTRAST_REQUIRE_DATA("las/sample_c.las");
  iotest::TempDir dir;
  const std::filesystem::path input = data("las/sample_c.las"); // 16-bit colors
  writePart(data("las/autzen_trim.las"), dir / "a.las", 0, 1'000);
  io::LodBuildOptions options;
  options.averageColors = false;
  const Result r = buildFiles({dir / "a.las", input}, options, dir / "t");
  std::vector<PointRecord> expected = readRecords(dir / "a.las");
  for (PointRecord& q : expected)
    for (uint16_t& c : q.rgb)
      c = uint16_t(c * 257);
  std::vector<PointRecord> got;
  for (const WrittenNode& node : r.sink.nodes)
    got.insert(got.end(), node.records.begin(), node.records.end());
  std::multiset<std::array<uint16_t, 3>> want, have;
  for (const PointRecord& q : expected)
    want.insert({q.rgb[0], q.rgb[1], q.rgb[2]});
  for (const PointRecord& q : readRecords(input))
    want.insert({q.rgb[0], q.rgb[1], q.rgb[2]});
  for (const PointRecord& q : got)
    have.insert({q.rgb[0], q.rgb[1], q.rgb[2]});
  EXPECT_EQ(have, want);
  EXPECT_GT(r.report.metadata.fields.colorMax, 255);
}

TEST(LodBuilder, InterruptedBuildLeavesNothing) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  iotest::TempDir dir;
  std::atomic<bool> cancel{false};
  io::LodBuildOptions options;
  options.cancel = &cancel;
  options.progress = false;
  options.memoryBytes = 1 << 20;
  io::OctreeBuilder builder({data("las/autzen_trim.las")}, options);
  builder.scan();
  cancel = true;
  MemorySink sink;
  EXPECT_THROW(builder.build(sink, dir / "t"), Interrupted);
  EXPECT_FALSE(std::filesystem::exists(dir / "t"));
}

TEST(LodBuilder, NoPointsIsAnInputError) {
  POINTRAST_REQUIRE_DATA("las/no-points.las");
  iotest::TempDir dir;
  io::LodBuildOptions options;
  options.progress = false;
  io::OctreeBuilder builder({data("las/no-points.las")}, options);
  EXPECT_THROW(builder.scan(), InputError);
  EXPECT_THROW(io::OctreeBuilder({}, options), InputError);
}

} // namespace

// LAZ decoding against the LAS twins and record hashes in shared/data (README: "decodes to exactly").
#include <map>
#include <thread>

#include "io/io_test_util.h"
#include "io/las/las_format.h"
#include "io/las/las_records.h"
#include "io/las/laz_reader.h"
#include "io/sha256.h"

using pointrast::InputError;
using pointrast::PointCloud;
using namespace pointrast::io;
using iotest::data;
using iotest::quiet;

namespace {

// The point records of an uncompressed LAS file, as bytes.
std::vector<uint8_t> lasRecords(const std::string& file) {
  detail::InputFile in(data(file));
  const detail::LasHeader hd = detail::readLasHeader(in);
  std::vector<uint8_t> bytes(hd.pointCount * hd.recordLength);
  in.readAt(hd.pointOffset, bytes.data(), bytes.size());
  return bytes;
}

struct Twin {
  const char* laz;
  const char* las;
  uint64_t points;
  const char* sha256; // of all decoded records (shared/data/README.md)
};

const Twin kTwins[] = {
    {"laz/simple.laz", "las/1.2-with-color.las", 1065,
     "0717948a72e6bf719db8d96ded1e76b760d73fb683347ebe3dd603832e3d5015"},
    {"laz/autzen_trim.laz", "las/autzen_trim.las", 110000,
     "f4eb6d80bf1fa507ffdcdaa73606d09041982659a50ee3895957e0b2b347f54b"},
    {"laz/lone-star.copc.laz", "las/lone-star.copc.las", 518862,
     "fb81e03fca9a6e3569feb6aa6e9eb92ddbca58ac10cb29fc8ba5e7eec4027dd3"},
    {"laz/las_with_several_extra_byte_bloc.laz", "las/las_with_several_extra_byte_bloc.las", 697721,
     "c19b99bc99062598ede4bed3bc6648832211f51b80ac22c8095cb547d8836406"},
};

TEST(LazReader, DecodesToTheRecordsOfTheLasTwin) {
  POINTRAST_REQUIRE_DATA();
  for (const Twin& t : kTwins) {
    SCOPED_TRACE(t.laz);
    const std::vector<uint8_t> decoded = readLazRecords(data(t.laz));
    const std::vector<uint8_t> twin = lasRecords(t.las);
    ASSERT_GE(decoded.size(), twin.size());
    // Full twins compare every record, prefix twins (PF8, COPC) their first 100,000.
    EXPECT_TRUE(std::equal(twin.begin(), twin.end(), decoded.begin())) << "records differ from " << t.las;
    EXPECT_EQ(iotest::sha256Hex(decoded), t.sha256);
    EXPECT_EQ(decoded.size() % t.points, 0u);
  }
}

} // namespace

namespace {

// The first n points of two clouds hold the same values in every array the first one has.
void expectSamePoints(const PointCloud& a, const PointCloud& b, uint64_t n) {
  ASSERT_GE(a.size(), n);
  ASSERT_GE(b.size(), n);
  EXPECT_EQ(a.scale, b.scale);
  EXPECT_EQ(a.offset, b.offset);
  EXPECT_TRUE(std::equal(a.positions.begin(), a.positions.begin() + 3 * n, b.positions.begin()));
  ASSERT_EQ(a.colors.empty(), b.colors.empty());
  EXPECT_TRUE(std::equal(a.colors.begin(), a.colors.begin() + (a.colors.empty() ? 0 : n), b.colors.begin()));
  ASSERT_EQ(a.intensity.empty(), b.intensity.empty());
  if (!a.intensity.empty()) {
    EXPECT_TRUE(std::equal(a.intensity.begin(), a.intensity.begin() + n, b.intensity.begin()));
    EXPECT_TRUE(std::equal(a.classification.begin(), a.classification.begin() + n, b.classification.begin()));
    EXPECT_TRUE(std::equal(a.returnNumber.begin(), a.returnNumber.begin() + n, b.returnNumber.begin()));
  }
}

TEST(LazReader, ReadCloudEqualsTheLasTwin) {
  POINTRAST_REQUIRE_DATA();
  for (const Twin& t : kTwins) {
    SCOPED_TRACE(t.laz);
    const PointCloud laz = readCloud(data(t.laz), quiet());
    const PointCloud las = readCloud(data(t.las), quiet());
    EXPECT_EQ(laz.size(), t.points);
    expectSamePoints(las, laz, las.size());
    if (las.size() == laz.size()) {
      EXPECT_EQ(laz.bounds.min, las.bounds.min);
      EXPECT_EQ(laz.bounds.max, las.bounds.max);
    }
  }
}

void append(PointCloud& to, const PointCloud& part) {
  to.scale = part.scale;
  to.offset = part.offset;
  to.positions.insert(to.positions.end(), part.positions.begin(), part.positions.end());
  to.colors.insert(to.colors.end(), part.colors.begin(), part.colors.end());
  to.intensity.insert(to.intensity.end(), part.intensity.begin(), part.intensity.end());
  to.classification.insert(to.classification.end(), part.classification.begin(), part.classification.end());
  to.returnNumber.insert(to.returnNumber.end(), part.returnNumber.begin(), part.returnNumber.end());
  to.pointSourceId.insert(to.pointSourceId.end(), part.pointSourceId.begin(), part.pointSourceId.end());
}

// Runs of records cut anywhere (inside chunks, on their edges, one point, past the end) read by
// readLazRange() join to the whole file, fixed and variable chunks alike.
TEST(LazReader, RangesJoinToTheWholeFile) {
  POINTRAST_REQUIRE_DATA();
  for (const char* file :
       {"laz/autzen_trim.laz", "laz/lone-star.copc.laz", "laz/las_with_several_extra_byte_bloc.laz"}) {
    SCOPED_TRACE(file);
    const PointCloud whole = readCloud(data(file), quiet());
    const uint64_t n = whole.size();
    const std::vector<uint64_t> cuts = {0, 1, 10240, 49999, 50000, 50001, n / 2, n - 1, n};
    PointCloud joined;
    for (size_t i = 0; i + 1 < cuts.size(); ++i) {
      const PointCloud part = readLazRange(data(file), quiet(), cuts[i], cuts[i + 1] - cuts[i], nullptr);
      ASSERT_EQ(part.size(), cuts[i + 1] - cuts[i]) << cuts[i];
      for (uint64_t p = 0; p < part.size(); ++p)
        for (int a = 0; a < 3; ++a) {
          ASSERT_GE(part.world(p)[a], part.bounds.min[a] - 1e-6);
          ASSERT_LE(part.world(p)[a], part.bounds.max[a] + 1e-6);
        }
      append(joined, part);
    }
    ASSERT_EQ(joined.size(), n);
    expectSamePoints(whole, joined, n);
    EXPECT_EQ(readLazRange(data(file), quiet(), n, 5, nullptr).size(), 0u);
    EXPECT_EQ(readLazRange(data(file), quiet(), n - 1, 100, nullptr).size(), 1u);
    // The whole file read with its color depths reported: nothing converted as 8-bit where it is 16-bit.
    LazColorDepths depths;
    PointCloud reported = readLazRange(data(file), quiet(), 0, UINT64_MAX, &depths);
    if (depths.any16) blackenEightBit(reported, depths);
    expectSamePoints(whole, reported, n);
  }
}

TEST(LazReader, SameOutputOnOneAndManyThreads) {
  POINTRAST_REQUIRE_DATA();
  for (const char* file : {"laz/autzen_trim.laz", "laz/las_with_several_extra_byte_bloc.laz"}) {
    SCOPED_TRACE(file);
    EXPECT_EQ(readLazRecords(data(file), 1), readLazRecords(data(file), 7));
    detail::setLazThreads(1);
    const PointCloud one = readCloud(data(file), quiet());
    detail::setLazThreads(5);
    const PointCloud many = readCloud(data(file), quiet());
    detail::setLazThreads(0);
    ASSERT_EQ(one.size(), many.size());
    expectSamePoints(one, many, one.size());
    EXPECT_EQ(one.bounds.min, many.bounds.min);
    EXPECT_EQ(one.bounds.max, many.bounds.max);
  }
}

TEST(LazReader, PointSourceServesChunksInFileOrderFromManyThreads) {
  POINTRAST_REQUIRE_DATA();
  const char* file = "laz/las_with_several_extra_byte_bloc.laz";
  const std::unique_ptr<PointSource> source = openPointSource(data(file));
  const PointSourceInfo& info = source->info();
  EXPECT_EQ(info.pointCount, 697721u);
  EXPECT_TRUE(info.fields.color && info.fields.intensity && info.fields.classification);
  const std::vector<PointPiece>& pieces = source->pieces();
  ASSERT_EQ(pieces.size(), 14u);
  uint64_t next = 0;
  for (size_t i = 0; i < pieces.size(); ++i) {
    EXPECT_EQ(pieces[i].first, next);
    EXPECT_GT(source->pieceBytes(i), 0u);
    next += pieces[i].count;
  }
  EXPECT_EQ(next, info.pointCount);
  // Pieces read concurrently (in reverse on half the threads) equal the records of the sequential decode.
  const std::vector<uint8_t> records = readLazRecords(data(file), 1);
  std::vector<std::vector<pointrast::PointRecord>> got(pieces.size());
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (size_t k = 0; k < pieces.size(); ++k) {
        const size_t i = t % 2 ? pieces.size() - 1 - k : k;
        if (i % 4 == size_t(t)) source->readPiece(i, got[i]);
      }
    });
  for (std::thread& t : threads)
    t.join();
  for (size_t i = 0; i < pieces.size(); ++i) {
    ASSERT_EQ(got[i].size(), pieces[i].count);
    for (size_t k = 0; k < got[i].size(); k += 997) {
      const pointrast::PointRecord want =
          detail::toPointRecord(records.data() + (pieces[i].first + k) * 41, true, 30);
      ASSERT_EQ(got[i][k], want) << "piece " << i << " point " << k;
    }
  }
}

TEST(LazReader, ProbeDescribesTheCompression) {
  POINTRAST_REQUIRE_DATA("laz/las_with_several_extra_byte_bloc.laz");
  const FileInfo info = probeFile(data("laz/las_with_several_extra_byte_bloc.laz"));
  EXPECT_STREQ(info.format->name, "LAZ");
  EXPECT_EQ(info.pointCount, 697721u);
  EXPECT_EQ(info.colorBits, 16);
  std::map<std::string, std::string> extra(info.extra.begin(), info.extra.end());
  EXPECT_EQ(extra["items"], "POINT14 v3, RGBNIR14 v3, BYTE14 v3 (3 B)");
  EXPECT_EQ(extra["chunks"], "14 of 50000 points");
  EXPECT_NE(extra["compression"].find("layered chunks"), std::string::npos);
  const FileInfo copc = probeFile(data("laz/lone-star.copc.laz"));
  std::map<std::string, std::string> copcExtra(copc.extra.begin(), copc.extra.end());
  EXPECT_NE(copcExtra["chunks"].find("variable size"), std::string::npos);
  EXPECT_EQ(probeFile(data("laz/autzen_trim.laz")).colorBits, 8);
}

TEST(LazReader, RefusesWhatItDoesNotDecodeWithOneLine) {
  POINTRAST_REQUIRE_DATA("laz/simple-laszip-compressor-version-1.2r0.laz");
  try {
    readCloud(data("laz/simple-laszip-compressor-version-1.2r0.laz"), quiet());
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("LASzip 1.x"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

} // namespace

// PointSource: LAS pieces decode to the records readLas reads (integers, raw color values, attributes),
// whatever the piece size and the thread that reads them; PLY/XYZ are served from one read; formats that
// hold no points are refused with one sentence.
#include <algorithm>
#include <thread>

#include "io/io_test_util.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/las/las_source.h"
#include "io/point_source.h"

namespace {

using namespace pointrast;
using namespace pointrast::io;
using iotest::data;
using iotest::quiet;

// Reads every piece from two threads, one from the front and one from the back (together they take
// each piece once), into file order.
std::vector<PointRecord> readAll(const PointSource& source) {
  const auto& pieces = source.pieces();
  std::vector<std::vector<PointRecord>> parts(pieces.size());
  std::atomic<size_t> front{0};
  std::atomic<ptrdiff_t> back{static_cast<ptrdiff_t>(pieces.size()) - 1};
  std::atomic<size_t> taken{0};
  auto worker = [&](bool forward) {
    for (;;) {
      if (taken.fetch_add(1) >= pieces.size()) return;
      size_t i = forward ? front.fetch_add(1) : static_cast<size_t>(back.fetch_sub(1));
      if (i < pieces.size()) source.readPiece(i, parts[i]);
    }
  };
  std::thread other(worker, false);
  worker(true);
  other.join();
  std::vector<PointRecord> all;
  uint64_t next = 0;
  for (size_t i = 0; i < pieces.size(); ++i) {
    EXPECT_EQ(pieces[i].first, next);
    EXPECT_EQ(parts[i].size(), pieces[i].count);
    next += pieces[i].count;
    all.insert(all.end(), parts[i].begin(), parts[i].end());
  }
  EXPECT_EQ(next, source.info().pointCount);
  return all;
}

struct PieceSize {
  explicit PieceSize(uint64_t n) { detail::setPieceRecords(n); }
  ~PieceSize() { detail::setPieceRecords(0); }
};

class LasSourceFiles : public ::testing::TestWithParam<const char*> {};

TEST_P(LasSourceFiles, PiecesDecodeToTheRecordsOfTheFile) {
  POINTRAST_REQUIRE_DATA();
  const std::filesystem::path path = data(GetParam());
  PieceSize small(777); // pieces that end mid-file and a short last piece
  std::unique_ptr<PointSource> source = openPointSource(path);
  const PointSourceInfo& info = source->info();
  PointCloud cloud = readLas(path, quiet());
  ASSERT_EQ(info.pointCount, cloud.size());
  EXPECT_EQ(info.scale, cloud.scale);
  EXPECT_EQ(info.offset, cloud.offset);
  EXPECT_EQ(info.fields.color, cloud.hasColor());
  EXPECT_TRUE(info.fields.intensity && info.fields.classification && info.fields.returnNumber &&
              info.fields.pointSourceId);
  EXPECT_GT(source->pieces().size(), 1u);
  std::vector<PointRecord> records = readAll(*source);
  ASSERT_EQ(records.size(), cloud.size());

  // The point source id is not in PointCloud: check it against the record bytes themselves.
  detail::InputFile file(path);
  const detail::LasHeader hd = detail::readLasHeader(file);
  const uint64_t idOffset = detail::las::isExtended(hd.pointFormat) ? 20 : 18;
  std::vector<uint8_t> bytes(static_cast<size_t>(hd.pointCount * hd.recordLength));
  file.readAt(hd.pointOffset, bytes.data(), bytes.size());

  uint16_t colorMax = 0;
  for (const PointRecord& r : records)
    colorMax = std::max({colorMax, r.rgb[0], r.rgb[1], r.rgb[2]});
  const int shift = colorMax > 255 ? 8 : 0;
  for (uint64_t i = 0; i < records.size(); ++i) {
    const PointRecord& r = records[i];
    ASSERT_EQ(r.x, cloud.positions[3 * i]) << i;
    ASSERT_EQ(r.y, cloud.positions[3 * i + 1]) << i;
    ASSERT_EQ(r.z, cloud.positions[3 * i + 2]) << i;
    ASSERT_EQ(r.intensity, cloud.intensity[i]) << i;
    ASSERT_EQ(r.classification, cloud.classification[i]) << i;
    ASSERT_EQ(r.returnNumber, cloud.returnNumber[i]) << i;
    ASSERT_EQ(r.pointSourceId, detail::loadLE<uint16_t>(&bytes[i * hd.recordLength + idOffset])) << i;
    if (cloud.hasColor())
      ASSERT_EQ(packRgba(r.rgb[0] >> shift & 0xFF, r.rgb[1] >> shift & 0xFF, r.rgb[2] >> shift & 0xFF),
                cloud.colors[i])
          << i;
    else
      ASSERT_TRUE(r.rgb[0] == 0 && r.rgb[1] == 0 && r.rgb[2] == 0) << i;
    ASSERT_EQ(source->pieceBytes(0), source->pieces()[0].count * hd.recordLength);
  }
}

INSTANTIATE_TEST_SUITE_P(Data, LasSourceFiles,
                         ::testing::Values("las/autzen_trim.las", "las/autzen_trim_7.las", "las/sample_c.las",
                                           "las/test1_4.las", "las/extrabytes.las"),
                         [](const auto& param) {
                           std::string name = std::filesystem::path(param.param).stem().string();
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

TEST(PointSource, SixteenBitColorsStayRaw) {
  POINTRAST_REQUIRE_DATA("las/sample_c.las");
  std::unique_ptr<PointSource> source = openPointSource(data("las/sample_c.las"));
  std::vector<PointRecord> records = readAll(*source);
  uint16_t lo = UINT16_MAX, hi = 0;
  for (const PointRecord& r : records)
    for (uint16_t c : r.rgb) {
      lo = std::min(lo, c);
      hi = std::max(hi, c);
    }
  // The data README: 16-bit values 35840..54272.
  EXPECT_EQ(lo, 35840);
  EXPECT_EQ(hi, 54272);
}

TEST(PointSource, NoPointsGivesNoPieces) {
  POINTRAST_REQUIRE_DATA("las/no-points.las");
  std::unique_ptr<PointSource> source = openPointSource(data("las/no-points.las"));
  EXPECT_EQ(source->info().pointCount, 0u);
  EXPECT_TRUE(source->pieces().empty());
}

TEST(PointSource, PlyAndXyzAreServedFromOneRead) {
  POINTRAST_REQUIRE_DATA();
  for (const char* name : {"ply/simple_binary.ply", "ply/simple_text.ply"}) {
    PieceSize small(3);
    std::unique_ptr<PointSource> source = openPointSource(data(name));
    PointCloud cloud = readCloud(data(name), quiet());
    std::vector<PointRecord> records = readAll(*source);
    ASSERT_EQ(records.size(), cloud.size()) << name;
    EXPECT_EQ(source->info().fields.color, cloud.hasColor());
    for (uint64_t i = 0; i < records.size(); ++i) {
      EXPECT_EQ(records[i].x, cloud.positions[3 * i]);
      EXPECT_EQ(records[i].z, cloud.positions[3 * i + 2]);
      if (cloud.hasColor()) {
        EXPECT_EQ(packRgba(records[i].rgb[0], records[i].rgb[1], records[i].rgb[2]), cloud.colors[i]);
      }
    }
  }
  iotest::TempDir dir;
  iotest::writeText(dir / "a.xyz", "1 2 3 10 20 30\n4 5 6 40 50 60\n");
  std::unique_ptr<PointSource> source = openPointSource(dir / "a.xyz");
  std::vector<PointRecord> records = readAll(*source);
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[1].rgb[0], 40);
  EXPECT_EQ(records[1].rgb[2], 60);
  EXPECT_EQ(source->info().fields.colorMax, 255);
}

TEST(PointSource, NonPointFilesAreRefusedWithOneSentence) {
  POINTRAST_REQUIRE_DATA();
  for (const char* name : {"mmpld/test_xyz_float_none.mmpld", "README.md"}) {
    try {
      openPointSource(data(name));
      ADD_FAILURE() << name << " was opened";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::filesystem::path(name).filename().string()),
                std::string::npos)
          << e.what();
    }
  }
}

} // namespace

namespace {

// Every prefix of a LAS file either opens and reads to the records it claims, or is refused with an
// InputError; never a crash or an overread (run under ASan in the sanitizer build).
TEST(PointSource, TruncatedLasIsReadOrRefused) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  const std::vector<uint8_t> bytes = iotest::readBytes(data("las/1.2-with-color.las"));
  iotest::TempDir dir;
  size_t opened = 0, refused = 0;
  for (size_t size = 0; size < bytes.size(); size += (size < 400 ? 7 : 977)) {
    iotest::writeBytes(dir / "t.las", bytes.data(), size);
    try {
      std::unique_ptr<PointSource> source = openPointSource(dir / "t.las");
      std::vector<PointRecord> records;
      uint64_t total = 0;
      for (size_t i = 0; i < source->pieces().size(); ++i) {
        source->readPiece(i, records);
        total += records.size();
      }
      EXPECT_EQ(total, source->info().pointCount);
      ++opened;
    } catch (const InputError&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 0u);
}

} // namespace

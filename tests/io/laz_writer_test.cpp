// LAZ encoder and lossless LAS/LAZ conversion: random records of every point format round-trip through
// the encoder and pointrast's decoder byte for byte; every LAS/LAZ file of the shared data converts to
// LAZ and LAS keeping its records; hostile inputs give one InputError and leave no file.
#include <map>
#include <random>

#include "io/io_test_util.h"
#include "io/las/las_format.h"
#include "io/las/laz_chunk.h"
#include "io/las/laz_encoder.h"
#include "io/las/laz_reader.h"
#include "io/laz_random_records.h"
#include "io/writer.h"

using pointrast::InputError;
using namespace pointrast::io;
namespace las = pointrast::io::detail::las;
using pointrast::io::detail::loadLE;
using pointrast::io::detail::storeLE;

namespace {

std::vector<uint8_t> decodeChunk(const laz::Layout& layout, const std::vector<uint8_t>& bytes,
                                 uint64_t count) {
  laz::ChunkDecoder decoder(layout);
  std::vector<uint8_t> out;
  decoder.decode(bytes.data(), bytes.size(), count, out);
  return out;
}

// The point records of a LAS or LAZ file as an uncompressed file holds them.
std::vector<uint8_t> recordsOf(const std::filesystem::path& path) {
  detail::InputFile file(path);
  if (detail::lasLooksCompressed(file)) return readLazRecords(path);
  const detail::LasHeader hd = detail::readLasHeader(file);
  std::vector<uint8_t> out(hd.pointCount * hd.recordLength);
  file.readAt(hd.pointOffset, out.data(), out.size());
  return out;
}

detail::LasHeader headerOf(const std::filesystem::path& path) {
  detail::InputFile file(path);
  return detail::readLasHeader(file, true);
}

// The VLRs other than LASzip's and COPC's, as (user id, record id) -> payload.
std::map<std::pair<std::string, uint16_t>, std::vector<uint8_t>> vlrsOf(const std::filesystem::path& path) {
  detail::InputFile file(path);
  const detail::LasHeader hd = detail::readLasHeader(file, true);
  std::map<std::pair<std::string, uint16_t>, std::vector<uint8_t>> out;
  for (const detail::LasVlr& v : hd.vlrs) {
    if (v.userId == "laszip encoded" || v.userId == "copc") continue;
    std::vector<uint8_t> payload(v.length);
    file.readAt(v.dataOffset, payload.data(), payload.size());
    out[{v.userId, v.recordId}] = payload;
  }
  return out;
}

struct FormatCase {
  int pointFormat;
  uint16_t extraBytes;
};

class LazEncoderFormats : public ::testing::TestWithParam<FormatCase> {};

TEST_P(LazEncoderFormats, RandomRecordsRoundTripThroughTheDecoder) {
  const FormatCase c = GetParam();
  const uint16_t rl = uint16_t(las::kRecordSize[size_t(c.pointFormat)] + c.extraBytes);
  const laz::Layout layout = laz::encoderLayout(c.pointFormat, rl, 50000);
  laz::ChunkEncoder encoder(layout);
  for (uint64_t n : {uint64_t(1), uint64_t(2), uint64_t(7), uint64_t(5000)}) {
    for (uint32_t seed = 1; seed <= 3; ++seed) {
      const std::vector<uint8_t> records = iotest::randomRecords(c.pointFormat, rl, n, seed);
      const std::vector<uint8_t> bytes = encoder.encode(records.data(), n);
      ASSERT_EQ(decodeChunk(layout, bytes, n), records)
          << "format " << c.pointFormat << ", " << n << " points";
    }
  }
  // Constant records: every layer but XY written empty.
  std::vector<uint8_t> same = iotest::randomRecords(c.pointFormat, rl, 1, 9);
  for (int i = 0; i < 99; ++i)
    same.insert(same.end(), same.begin(), same.begin() + rl);
  EXPECT_EQ(decodeChunk(layout, encoder.encode(same.data(), 100), 100), same);
}

INSTANTIATE_TEST_SUITE_P(AllFormats, LazEncoderFormats,
                         ::testing::Values(FormatCase{0, 0}, FormatCase{1, 0}, FormatCase{2, 0},
                                           FormatCase{3, 0}, FormatCase{3, 5}, FormatCase{0, 1},
                                           FormatCase{6, 0}, FormatCase{7, 0}, FormatCase{8, 0},
                                           FormatCase{6, 3}, FormatCase{7, 12}));

// A file of random records through LasFileWriter, fixed and variable chunks, read back by readLazRecords.
TEST(LazWriter, FixedAndVariableChunksReadBack) {
  iotest::TempDir dir;
  for (int format : {3, 7}) {
    const uint16_t rl = uint16_t(las::kRecordSize[size_t(format)] + 2);
    const std::vector<uint8_t> records = iotest::randomRecords(format, rl, 23456, 5);
    for (uint32_t chunkSize : {uint32_t(1000), uint32_t(50000), kVariableChunkSize}) {
      LasFileSetup setup;
      setup.header.assign(las::kHeaderSize14, 0);
      std::memcpy(setup.header.data(), "LASF", 4);
      setup.header[las::kVersionMajor] = 1;
      setup.header[las::kVersionMinor] = 4;
      storeLE<uint16_t>(setup.header.data() + las::kHeaderSizeField, uint16_t(las::kHeaderSize14));
      for (int a = 0; a < 3; ++a)
        storeLE<double>(setup.header.data() + las::kScale + 8 * a, 0.01);
      setup.pointFormat = format;
      setup.recordLength = rl;
      setup.laz = true;
      setup.chunkSize = chunkSize;
      const auto out = dir / ("f" + std::to_string(format) + "-" + std::to_string(chunkSize) + ".laz");
      {
        LasFileWriter writer(out, setup);
        // Uneven pieces: 1, 2, 3... points (one chunk each with variable chunks).
        uint64_t at = 0;
        for (uint64_t n = 1; at < 23456; ++n) {
          const uint64_t k = std::min<uint64_t>(n * 37, 23456 - at);
          writer.writeChunk(records.data() + at * rl, k);
          at += k;
        }
        writer.commit();
      }
      EXPECT_EQ(readLazRecords(out, 1), records) << out;
      EXPECT_EQ(readLazRecords(out, 4), records) << out;
      const detail::LasHeader hd = headerOf(out);
      EXPECT_EQ(hd.pointCount, 23456u);
      EXPECT_EQ(hd.pointFormat, format);
    }
  }
}

// Every LAS/LAZ file of the shared data to LAZ and to LAS: the same records, byte for byte, the same
// VLRs (but LASzip's and COPC's), the same header fields.
TEST(LazWriter, SharedDataConvertsLosslessly) {
  POINTRAST_REQUIRE_DATA();
  iotest::TempDir dir;
  int converted = 0;
  for (const char* folder : {"las", "laz"}) {
    for (const auto& entry : std::filesystem::directory_iterator(iotest::data(folder))) {
      const std::filesystem::path in = entry.path();
      const std::string ext = in.extension().string();
      if (ext != ".las" && ext != ".laz") continue;
      // LASzip 1.x files are refused by the reader; the conversion must refuse them the same way.
      if (in.filename().string().find("laszip-compressor-version-1") != std::string::npos) {
        EXPECT_THROW(convertLasFile(in, dir / "refused.laz"), InputError);
        EXPECT_FALSE(std::filesystem::exists(dir / "refused.laz"));
        continue;
      }
      SCOPED_TRACE(in.string());
      const std::vector<uint8_t> records = recordsOf(in);
      const detail::LasHeader inHeader = headerOf(in);
      for (const char* outExt : {".laz", ".las"}) {
        const auto out = dir / (in.stem().string() + outExt);
        const uint64_t written = convertLasFile(in, out);
        EXPECT_EQ(written, inHeader.pointCount);
        EXPECT_EQ(recordsOf(out), records) << out;
        const detail::LasHeader hd = headerOf(out);
        EXPECT_EQ(hd.pointFormat, inHeader.pointFormat);
        EXPECT_EQ(hd.recordLength, inHeader.recordLength);
        EXPECT_EQ(hd.versionMinor, inHeader.versionMinor);
        EXPECT_EQ(hd.pointCount, inHeader.pointCount);
        EXPECT_EQ(hd.scale, inHeader.scale);
        EXPECT_EQ(hd.offset, inHeader.offset);
        EXPECT_EQ(vlrsOf(out), vlrsOf(in));
        ++converted;
      }
    }
  }
  EXPECT_GE(converted, 2 * 18);
}

TEST(LazWriter, HostileInputsGiveOneError) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  iotest::TempDir dir;
  // A header whose point count promises more records than the file holds.
  std::vector<uint8_t> bytes = iotest::readBytes(iotest::data("las/1.2-with-color.las"));
  storeLE<uint32_t>(bytes.data() + las::kLegacyCount,
                    loadLE<uint32_t>(bytes.data() + las::kLegacyCount) + 1000);
  iotest::writeBytes(dir / "lying.las", bytes);
  EXPECT_THROW(convertLasFile(dir / "lying.las", dir / "lying.laz"), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "lying.laz"));
  EXPECT_FALSE(std::filesystem::exists(detail::partialPath(dir / "lying.laz")));

  // NaN scale.
  bytes = iotest::readBytes(iotest::data("las/1.2-with-color.las"));
  storeLE<double>(bytes.data() + las::kScale, std::nan(""));
  iotest::writeBytes(dir / "nan.las", bytes);
  EXPECT_THROW(convertLasFile(dir / "nan.las", dir / "nan.laz"), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "nan.laz"));

  // A LAZ file whose chunk table claims more points than its chunks code.
  bytes = iotest::readBytes(iotest::data("laz/simple.laz"));
  storeLE<uint32_t>(bytes.data() + las::kLegacyCount, loadLE<uint32_t>(bytes.data() + las::kLegacyCount) * 3);
  iotest::writeBytes(dir / "lying.laz", bytes);
  EXPECT_THROW(convertLasFile(dir / "lying.laz", dir / "out.las"), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "out.las"));

  // Waveform formats are refused unless the packets may go.
  bytes = iotest::readBytes(iotest::data("las/1.2-with-color.las"));
  detail::InputFile file(iotest::data("las/1.2-with-color.las"));
  const detail::LasHeader hd = detail::readLasHeader(file);
  std::vector<uint8_t> wave(bytes.begin(), bytes.begin() + hd.pointOffset);
  wave[las::kPointFormat] = 5;
  storeLE<uint16_t>(wave.data() + las::kRecordLength, 63);
  for (uint64_t i = 0; i < hd.pointCount; ++i) {
    const uint8_t* r = bytes.data() + hd.pointOffset + i * hd.recordLength;
    wave.insert(wave.end(), r, r + 34);
    wave.insert(wave.end(), 29, uint8_t(i));
  }
  iotest::writeBytes(dir / "wave.las", wave);
  try {
    convertLasFile(dir / "wave.las", dir / "wave.laz");
    FAIL() << "a waveform file converted without --drop-waveforms";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("waveform"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "wave.laz"));
  LasConvertOptions drop;
  drop.dropWaveforms = true;
  EXPECT_EQ(convertLasFile(dir / "wave.las", dir / "wave.laz", drop), hd.pointCount);
  EXPECT_EQ(recordsOf(dir / "wave.laz"), recordsOf(iotest::data("las/1.2-with-color.las")));
  EXPECT_EQ(headerOf(dir / "wave.laz").pointFormat, 3);
}

// LasRecordWriter (octree exports, clouds) writes LAZ when the name says so: the same records as LAS.
TEST(LazWriter, RecordWriterWritesLazByExtension) {
  iotest::TempDir dir;
  std::vector<pointrast::PointRecord> points(70000);
  std::mt19937 rng(3);
  for (auto& p : points) {
    p.x = int32_t(rng() % 100000);
    p.y = int32_t(rng() % 100000);
    p.z = int32_t(rng() % 1000);
    p.rgb[0] = uint16_t(rng());
    p.rgb[1] = uint16_t(rng());
    p.rgb[2] = uint16_t(88 * 256);
    p.intensity = uint16_t(rng());
    p.returnNumber = uint8_t(1 + rng() % 5);
    p.classification = uint8_t(rng() % 20);
    p.pointSourceId = uint16_t(rng());
  }
  pointrast::RecordFields fields;
  fields.color = fields.intensity = fields.classification = fields.returnNumber = fields.pointSourceId = true;
  for (LasFlavor flavor : {LasFlavor::Las12Pf3, LasFlavor::Las14Pf7}) {
    for (const char* name : {"r.las", "r.laz"}) {
      LasRecordWriter w(dir / name, glm::dvec3(0.01), glm::dvec3(0), fields, flavor);
      w.write(points.data(), points.size());
      w.commit();
    }
    EXPECT_EQ(recordsOf(dir / "r.laz"), recordsOf(dir / "r.las"));
    EXPECT_EQ(headerOf(dir / "r.laz").pointCount, points.size());
  }
}

} // namespace

namespace {

// Point format conversions: legacy formats through LAS 1.4's and back come back byte for byte; 1.4
// formats into legacy ones either come back byte for byte or are refused for what would be lost.
TEST(LazWriter, PointFormatConversionsAreExactOrRefused) {
  POINTRAST_REQUIRE_DATA();
  iotest::TempDir dir;
  static const int kTo14[] = {6, 6, 7, 7, 6, 7, 6, 7, 8, 6, 8};
  static const int kTo12[] = {0, 1, 2, 3, 1, 3, 1, 3, 3, 1, 3};
  int exact = 0, refused = 0;
  for (const char* folder : {"las", "laz"}) {
    for (const auto& entry : std::filesystem::directory_iterator(iotest::data(folder))) {
      const std::filesystem::path in = entry.path();
      if (in.extension() != ".las" && in.extension() != ".laz") continue;
      if (in.filename().string().find("laszip-compressor-version-1") != std::string::npos) continue;
      SCOPED_TRACE(in.string());
      const detail::LasHeader hd = headerOf(in);
      const int other = hd.pointFormat >= 6 ? kTo12[size_t(hd.pointFormat)] : kTo14[size_t(hd.pointFormat)];
      LasConvertOptions there;
      there.pointFormat = other;
      LasConvertOptions back;
      back.pointFormat = hd.pointFormat;
      try {
        convertLasFile(in, dir / "there.laz", there);
      } catch (const InputError& e) {
        EXPECT_LT(other, 6) << e.what(); // legacy to 1.4 never loses anything
        EXPECT_NE(std::string(e.what()).find("cannot hold"), std::string::npos) << e.what();
        EXPECT_FALSE(std::filesystem::exists(dir / "there.laz"));
        ++refused;
        continue;
      }
      EXPECT_EQ(headerOf(dir / "there.laz").pointFormat, other);
      convertLasFile(dir / "there.laz", dir / "back.las", back);
      EXPECT_EQ(recordsOf(dir / "back.las"), recordsOf(in));
      std::filesystem::remove(dir / "there.laz");
      ++exact;
    }
  }
  EXPECT_GE(exact, 10);
  std::printf("point format conversions: %d exact, %d refused\n", exact, refused);
}

} // namespace

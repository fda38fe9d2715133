// `convert` to LAZ and lossless LAS/LAZ conversion through the CLI: COPC and LAZ to LAS keep every record
// byte (16-bit colors as stored), LAS to LAZ to LAS comes back byte for byte, octrees export to LAZ as
// they do to LAS, and inputs the conversion would damage fail with one line, exit 1 and no file.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/las/laz_reader.h"
#include "io/potree_test_util.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using namespace pointrast;

const fs::path kData = pointrast::test::dataDir();

std::vector<uint8_t> recordsOf(const fs::path& path) {
  io::detail::InputFile file(path);
  if (io::detail::lasLooksCompressed(file)) return io::readLazRecords(path);
  const io::detail::LasHeader hd = io::detail::readLasHeader(file);
  std::vector<uint8_t> out(hd.pointCount * hd.recordLength);
  file.readAt(hd.pointOffset, out.data(), out.size());
  return out;
}

int pointFormatOf(const fs::path& path) {
  io::detail::InputFile file(path);
  return io::detail::readLasHeader(file, true).pointFormat;
}

void expectOneLineFailure(const CliResult& r, const fs::path& out) {
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_FALSE(r.signaled);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out)) << out;
  EXPECT_FALSE(fs::exists(io::detail::partialPath(out))) << out;
}

TEST(ConvertLazCli, CopcToLasKeepsEveryRecordByte) {
  POINTRAST_REQUIRE_DATA("laz/lone-star.copc.laz");
  const fs::path in = kData / "laz/lone-star.copc.laz";
  const fs::path out = pointrast::test::cliTempDir() / "lone-star.las";
  fs::remove(out);
  const CliResult r = runPointrast("convert -q " + in.string() + " " + out.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // 16-bit colors such as 88 * 256 stay 88 * 256 (not 88 * 257): every byte of every record is kept.
  EXPECT_EQ(recordsOf(out), recordsOf(in));
  EXPECT_EQ(pointFormatOf(out), pointFormatOf(in));
}

TEST(ConvertLazCli, LasToLazToLasComesBackByteForByte) {
  POINTRAST_REQUIRE_DATA();
  const fs::path dir = pointrast::test::cliTempDir();
  for (const char* name : {"las/autzen_trim_7.las", "las/extrabytes.las",
                           "las/las_with_several_extra_byte_bloc.las", "las/test1_4.las"}) {
    SCOPED_TRACE(name);
    const fs::path in = kData / name;
    const fs::path laz = dir / "round.laz", las = dir / "round.las";
    fs::remove(laz);
    fs::remove(las);
    CliResult r = runPointrast("convert -q " + in.string() + " " + laz.string() + " --chunk-size 1000");
    ASSERT_EQ(r.exitCode, 0) << r.err;
    r = runPointrast("convert -q " + laz.string() + " " + las.string());
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const std::vector<uint8_t> records = recordsOf(in);
    EXPECT_EQ(recordsOf(laz), records);
    EXPECT_EQ(recordsOf(las), records);
    const CliResult info = runPointrast("info " + laz.string());
    EXPECT_EQ(info.exitCode, 0) << info.err;
  }
}

TEST(ConvertLazCli, LasVersionAndPointFormatConvertTheRecords) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  const fs::path dir = pointrast::test::cliTempDir();
  const fs::path in = kData / "las/1.2-with-color.las";
  const fs::path up = dir / "up.laz", back = dir / "back.las";
  fs::remove(up);
  fs::remove(back);
  CliResult r = runPointrast("convert -q --las 1.4 " + in.string() + " " + up.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(pointFormatOf(up), 7); // format 3's GPS time and colors in LAS 1.4
  r = runPointrast("convert -q --point-format 3 " + up.string() + " " + back.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(recordsOf(back), recordsOf(in));
  // Colors do not fit format 1: refused, not dropped.
  expectOneLineFailure(
      runPointrast("convert -q --point-format 1 " + in.string() + " " + (dir / "pf1.las").string()),
      dir / "pf1.las");
}

TEST(ConvertLazCli, OctreeExportsToLazAsToLas) {
  const fs::path dir = pointrast::test::cliTempDir();
  const potreetest::Tree tree =
      potreetest::makeTree({.points = 5000, .depth = 4, .color16 = true, .seed = 5});
  fs::remove_all(dir / "laz-octree");
  io::PotreeWriteOptions o;
  potreetest::writeTree(tree, dir / "laz-octree", o);
  const fs::path las = dir / "octree.las", laz = dir / "octree.laz";
  fs::remove(las);
  fs::remove(laz);
  ASSERT_EQ(runPointrast("convert -q " + (dir / "laz-octree").string() + " " + las.string()).exitCode, 0);
  const CliResult r = runPointrast("convert -q " + (dir / "laz-octree").string() + " " + laz.string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(recordsOf(laz), recordsOf(las));
  EXPECT_EQ(recordsOf(laz).size(), 5000u * io::detail::las::kRecordSize[size_t(pointFormatOf(las))]);
}

TEST(ConvertLazCli, DamagingConversionsFailWithOneLine) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  const fs::path dir = pointrast::test::cliTempDir();
  // A point count that lies.
  std::vector<uint8_t> bytes = iotest::readBytes(kData / "las/1.2-with-color.las");
  const uint32_t count = io::detail::loadLE<uint32_t>(bytes.data() + io::detail::las::kLegacyCount);
  io::detail::storeLE<uint32_t>(bytes.data() + io::detail::las::kLegacyCount, count * 2);
  iotest::writeBytes(dir / "lying.las", bytes);
  fs::remove(dir / "lying.laz");
  expectOneLineFailure(
      runPointrast("convert -q " + (dir / "lying.las").string() + " " + (dir / "lying.laz").string()),
      dir / "lying.laz");

  // A NaN offset.
  bytes = iotest::readBytes(kData / "las/1.2-with-color.las");
  io::detail::storeLE<double>(bytes.data() + io::detail::las::kOffset + 8, std::nan(""));
  iotest::writeBytes(dir / "nan.las", bytes);
  expectOneLineFailure(
      runPointrast("convert -q " + (dir / "nan.las").string() + " " + (dir / "nan.laz").string()),
      dir / "nan.laz");

  // A waveform format: refused unless --drop-waveforms.
  bytes = iotest::readBytes(kData / "las/1.2-with-color.las");
  bytes[io::detail::las::kPointFormat] = 4; // 57-byte records: 28 (format 1) + 29 of wave packet
  const uint32_t offset = io::detail::loadLE<uint32_t>(bytes.data() + io::detail::las::kPointOffset);
  std::vector<uint8_t> wave(bytes.begin(), bytes.begin() + offset);
  io::detail::storeLE<uint16_t>(wave.data() + io::detail::las::kRecordLength, 57);
  const std::vector<uint8_t> plain = recordsOf(kData / "las/1.2-with-color.las");
  for (uint32_t i = 0; i < count; ++i) {
    wave.insert(wave.end(), plain.begin() + i * 34, plain.begin() + i * 34 + 28);
    wave.insert(wave.end(), 29, uint8_t(7));
  }
  iotest::writeBytes(dir / "wave.las", wave);
  fs::remove(dir / "wave.laz");
  const CliResult refused =
      runPointrast("convert -q " + (dir / "wave.las").string() + " " + (dir / "wave.laz").string());
  expectOneLineFailure(refused, dir / "wave.laz");
  EXPECT_NE(refused.err.find("--drop-waveforms"), std::string::npos) << refused.err;
  const CliResult dropped = runPointrast("convert -q --drop-waveforms " + (dir / "wave.las").string() + " " +
                                         (dir / "wave.laz").string());
  ASSERT_EQ(dropped.exitCode, 0) << dropped.err;
  EXPECT_EQ(pointFormatOf(dir / "wave.laz"), 1);
  const std::vector<uint8_t> got = recordsOf(dir / "wave.laz");
  ASSERT_EQ(got.size(), size_t(count) * 28);
  for (uint32_t i = 0; i < count; ++i)
    ASSERT_EQ(0, std::memcmp(got.data() + i * 28, plain.data() + i * 34, 28)) << "record " << i;

  // Neither LAS nor LAZ.
  const CliResult ext =
      runPointrast("convert -q " + (kData / "laz/simple.laz").string() + " " + (dir / "x.ply").string());
  expectOneLineFailure(ext, dir / "x.ply");
}

} // namespace

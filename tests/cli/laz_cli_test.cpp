// LAZ through the CLI: a compressed file renders exactly as its uncompressed twin, info describes the
// compression, and encodings pointrast does not decode fail with one line.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::runPointrast;
using pointrast::test::slurp;

const fs::path kData = pointrast::test::dataDir();

std::string binary(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(LazCli, RenderOfLazIsBitIdenticalToRenderOfItsLasTwin) {
  POINTRAST_REQUIRE_DATA("laz/autzen_trim.laz");
  const fs::path dir = pointrast::test::cliTempDir();
  const fs::path laz = dir / "autzen_laz.png", las = dir / "autzen_las.png";
  const std::string args = " --width 320 --height 240 --frames 1";
  auto r1 = runPointrast("render " + (kData / "laz/autzen_trim.laz").string() + " -o " + laz.string() + args);
  ASSERT_EQ(r1.exitCode, 0) << r1.err;
  auto r2 = runPointrast("render " + (kData / "las/autzen_trim.las").string() + " -o " + las.string() + args);
  ASSERT_EQ(r2.exitCode, 0) << r2.err;
  const std::string a = binary(laz), b = binary(las);
  ASSERT_GT(a.size(), 8u);
  EXPECT_TRUE(a == b) << "the LAZ render differs from the LAS render";
}

TEST(LazCli, InfoDescribesTheCompression) {
  POINTRAST_REQUIRE_DATA("laz/autzen_trim.laz");
  auto r = runPointrast("info " + (kData / "laz/autzen_trim.laz").string() + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* key :
       {"\"format\":\"LAZ\"", "\"points\":110000", "\"color_bits\":8", "\"scale\"",
        "\"items\":\"POINT10 v2, GPSTIME11 v2, RGB12 v2\"", "\"chunks\":\"3 of 50000 points\""})
    EXPECT_NE(r.out.find(key), std::string::npos) << key << " missing in " << r.out;
}

TEST(LazCli, UndecodedEncodingsFailWithOneLine) {
  POINTRAST_REQUIRE_DATA("laz/simple-laszip-compressor-version-1.2r0.laz");
  auto r = runPointrast("info " + (kData / "laz/simple-laszip-compressor-version-1.2r0.laz").string());
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_FALSE(r.signaled);
  EXPECT_NE(r.err.find("LASzip 1.x"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
}

} // namespace

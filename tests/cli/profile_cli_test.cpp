// `profile` on a real file: the strip's LAS holds exactly the points the test finds within W/2 of the
// polyline by its own geometry (records byte for byte), the CSV's distances along the line are right, and
// a bad line is one line of error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "las_records_test_util.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using namespace pointrast::test::las_records;

const fs::path kData = pointrast::test::dataDir();

// The strip of profile's --help: horizontal distance to the nearest point of the nearest segment.
struct Station {
  double offset, distance;
};
Station nearest(const std::vector<double>& line, double x, double y) {
  Station best{1e300, 0};
  double along = 0;
  for (size_t i = 0; i + 3 < line.size(); i += 2) {
    const double ax = line[i], ay = line[i + 1], bx = line[i + 2], by = line[i + 3];
    const double dx = bx - ax, dy = by - ay, len = std::hypot(dx, dy);
    double t = ((x - ax) * dx + (y - ay) * dy) / (len * len);
    t = std::clamp(t, 0.0, 1.0);
    const double d = std::hypot(x - (ax + t * dx), y - (ay + t * dy));
    if (d < best.offset) best = {d, along + t * len};
    along += len;
  }
  return best;
}

TEST(ProfileCli, LasAndCsvHoldTheStrip) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const fs::path in = kData / "las/autzen_trim.las";
  const fs::path las = pointrast::test::cliTempDir() / "profile.las",
                 csv = pointrast::test::cliTempDir() / "profile.csv",
                 png = pointrast::test::cliTempDir() / "profile.png";
  const std::vector<double> line = {636100, 849000, 636700, 849300, 637100, 849300};
  const double width = 8;
  const CliResult r = runPointrast(
      "profile -q " + in.string() + " --line 636100,849000,636700,849300,637100,849300 --width 8 --las " +
      las.string() + " --csv " + csv.string() + " -o " + png.string() + " --size 400x200");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Las input = readInput(in);
  const std::vector<std::string> expected =
      select(input, [&](const Fields& f) { return nearest(line, f.x, f.y).offset <= width / 2; });
  EXPECT_GT(expected.size(), 100u);
  expectLasHolds(las, expected);
  EXPECT_GT(fs::file_size(png), 1000u);

  std::ifstream rows(csv);
  std::string header, row;
  std::getline(rows, header);
  EXPECT_EQ(header, "distance,elevation,x,y,z,intensity,classification,return_number,gps_time,r,g,b");
  size_t count = 0;
  while (std::getline(rows, row)) {
    double distance = 0, elevation = 0, x = 0, y = 0, z = 0;
    ASSERT_EQ(std::sscanf(row.c_str(), "%lf,%lf,%lf,%lf,%lf", &distance, &elevation, &x, &y, &z), 5) << row;
    const Station s = nearest(line, x, y);
    EXPECT_LE(s.offset, width / 2 + 1e-6) << row;
    EXPECT_NEAR(distance, s.distance, 1e-5) << row;
    EXPECT_EQ(elevation, z) << row;
    ++count;
  }
  EXPECT_EQ(count, expected.size());
}

TEST(ProfileCli, BadLineIsOneLine) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const fs::path csv = pointrast::test::cliTempDir() / "bad_profile.csv";
  fs::remove(csv);
  expectOneLineFailure(runPointrast("profile -q " + (kData / "las/autzen_trim.las").string() +
                                    " --line 636100,849000 --width 8 --csv " + csv.string()),
                       csv, "--line");
  expectOneLineFailure(runPointrast("profile -q " + (kData / "las/autzen_trim.las").string() +
                                    " --line 636100,849000,636700,849300 --width 0 --csv " + csv.string()),
                       csv, "--width");
}

} // namespace

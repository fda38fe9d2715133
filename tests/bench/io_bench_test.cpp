// bench-io's decoding and encoding figures on a small real LAZ file converted to point formats 3 and 7:
// every timing is there and positive, in the JSON and the Markdown report. No figure is compared with a
// threshold: a shared CI machine gives no stable one.
#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bench/io_bench.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using namespace pointrast::bench;

IoBenchConfig smallConfig(const char* name) {
  IoBenchConfig config;
  config.inputs = {pointrast::test::dataDir() / "laz/simple.laz"};
  config.threads = {1, 2};
  config.repeats = 1;
  config.readCloud = false;
  config.pointFormats = {3, 7};
  config.workDir = fs::temp_directory_path() /
                   ("pointrast-io-bench-" + std::string(name) + "-" + std::to_string(::getpid()));
  return config;
}

void expectTiming(const nlohmann::json& t, unsigned threads, uint64_t points) {
  EXPECT_EQ(t["threads"].get<unsigned>(), threads) << t.dump();
  EXPECT_GT(t["median_s"].get<double>(), 0.0) << t.dump();
  EXPECT_LE(t["best_s"].get<double>(), t["median_s"].get<double>()) << t.dump();
  EXPECT_GT(t["cpu_s"].get<double>(), 0.0) << t.dump();
  EXPECT_GT(t["points_per_s"].get<double>(), 0.0) << t.dump();
  EXPECT_GT(t["points_per_s_per_thread"].get<double>(), 0.0) << t.dump();
  EXPECT_GT(t["points_per_cpu_s"].get<double>(), 0.0) << t.dump();
  EXPECT_NEAR(t["points_per_s"].get<double>() * t["median_s"].get<double>(), double(points), 1.0);
}

TEST(IoBench, EncodingIsTimedForPointFormats3And7AtEveryThreadCount) {
  POINTRAST_REQUIRE_DATA("laz/simple.laz");
  const IoBenchConfig config = smallConfig("encode");
  const IoBenchRun run = runIoBench(config, false);
  fs::remove_all(config.workDir);
  const nlohmann::json j = ioRunJson(run, "pointrast bench-io simple.laz", "2026-01-01T00:00:00Z");
  ASSERT_EQ(j["results"].size(), 2u) << j.dump();
  const char* expectedFormats[] = {"point format 3", "point format 7"};
  for (size_t i = 0; i < 2; ++i) {
    const nlohmann::json& r = j["results"][i];
    EXPECT_NE(r["layout"].get<std::string>().find(expectedFormats[i]), std::string::npos) << r["layout"];
    const uint64_t points = r["points"].get<uint64_t>();
    EXPECT_GT(points, 0u);
    ASSERT_EQ(r["decode"].size(), 2u) << r.dump();
    ASSERT_TRUE(r.contains("encode")) << r.dump();
    ASSERT_EQ(r["encode"].size(), 2u) << r.dump();
    for (size_t t = 0; t < 2; ++t) {
      expectTiming(r["decode"][t], unsigned(t + 1), points);
      expectTiming(r["encode"][t], unsigned(t + 1), points);
    }
    // The encoder compresses: fewer bytes than the raw records, more than nothing.
    const uint64_t encoded = r["encoded_bytes"].get<uint64_t>();
    EXPECT_GT(encoded, 0u);
    EXPECT_LT(encoded, points * 34u);
  }
  const std::string md = ioMarkdownReport(run, "pointrast bench-io simple.laz", "2026-01-01T00:00:00Z");
  EXPECT_NE(md.find("Encoding the same raw LAS records"), std::string::npos) << md;
  EXPECT_NE(md.find("| simple-pf7.laz | "), std::string::npos) << md;
}

TEST(IoBench, EncodingCanBeLeftOut) {
  POINTRAST_REQUIRE_DATA("laz/simple.laz");
  IoBenchConfig config = smallConfig("no-encode");
  config.encode = false;
  config.pointFormats = {3};
  config.threads = {1};
  const IoBenchRun run = runIoBench(config, false);
  fs::remove_all(config.workDir);
  ASSERT_EQ(run.results.size(), 1u);
  EXPECT_TRUE(run.results[0].encode.empty());
  EXPECT_EQ(run.results[0].decode.size(), 1u);
  const nlohmann::json j =
      ioRunJson(run, "pointrast bench-io simple.laz --no-encode", "2026-01-01T00:00:00Z");
  EXPECT_FALSE(j["results"][0].contains("encode")) << j.dump();
  EXPECT_EQ(ioMarkdownReport(run, "c", "d").find("Encoding the same"), std::string::npos);
}

// A point format the points cannot take (simple.laz has colors; point format 6 has none) stops the run
// before any file is timed, and leaves no converted file behind.
TEST(IoBench, AFormatThePointsCannotTakeStopsBeforeAnyTiming) {
  POINTRAST_REQUIRE_DATA("laz/simple.laz");
  IoBenchConfig config = smallConfig("bad-format");
  config.pointFormats = {3, 6};
  config.threads = {1};
  testing::internal::CaptureStderr();
  EXPECT_ANY_THROW(runIoBench(config, true));
  const std::string progress = testing::internal::GetCapturedStderr();
  EXPECT_EQ(progress.find("points/s"), std::string::npos) << progress;
  std::error_code error;
  EXPECT_TRUE(!fs::exists(config.workDir) || fs::is_empty(config.workDir, error)) << config.workDir;
  fs::remove_all(config.workDir);
}

} // namespace

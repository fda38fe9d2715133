// LAZ files pointrast writes, decoded by an independent implementation: laz-perf (LASzip's format in
// WebAssembly, from npm, installed by scripts/web-test-setup.sh) run by node through
// tests/web/laz_records.mjs, which prints the SHA-256 of the decoded records. Every LAS/LAZ file of the
// shared data converted to LAZ, and random records of every point format in fixed and variable chunks,
// must hash the same as the records written. In CI (CI=true) a missing node or laz-perf fails the tests.
#include <cstdio>
#include <cstdlib>
#include <sys/wait.h>

#include "io/io_test_util.h"
#include "io/las/las_format.h"
#include "io/las/laz_reader.h"
#include "io/laz_random_records.h"
#include "io/sha256.h"
#include "io/writer.h"

using namespace pointrast::io;
namespace las = pointrast::io::detail::las;
using pointrast::io::detail::storeLE;

namespace {

const std::string kWebDir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";

std::string run(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) {
    status = -1;
    return out;
  }
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0)
    out.append(buffer, n);
  status = pclose(pipe);
  return out;
}

// "COUNT SHA256" of the records laz-perf decodes from the file.
std::string lazPerfRecords(const std::filesystem::path& file) {
  int status = 0;
  std::string out = run("cd '" + kWebDir + "' && node laz_records.mjs '" + file.string() + "' 2>&1", status);
  EXPECT_EQ(status, 0) << "laz-perf could not decode " << file << ":\n" << out;
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r'))
    out.pop_back();
  return out;
}

std::string expected(const std::vector<uint8_t>& records, size_t recordLength) {
  return std::to_string(records.size() / recordLength) + " " +
         iotest::sha256Hex(records.data(), records.size());
}

// The input's records: decoded by pointrast for LAZ, as stored for LAS.
std::vector<uint8_t> inputRecords(const std::filesystem::path& path) {
  detail::InputFile file(path);
  if (detail::lasLooksCompressed(file)) return readLazRecords(path);
  const detail::LasHeader hd = detail::readLasHeader(file);
  std::vector<uint8_t> out(hd.pointCount * hd.recordLength);
  file.readAt(hd.pointOffset, out.data(), out.size());
  return out;
}

class LazPerf : public ::testing::Test {
protected:
  void SetUp() override {
    int status = 0;
    run("node --version >/dev/null 2>&1", status);
    const bool node = status == 0;
    const bool lazPerf = std::filesystem::exists(kWebDir + "/node_modules/laz-perf/package.json");
    if (node && lazPerf) return;
    const char* ci = std::getenv("CI");
    const std::string missing = !node ? "node is not installed (scripts/install-deps.sh)"
                                      : "laz-perf is not installed: run scripts/web-test-setup.sh";
    if (ci && std::string(ci) == "true")
      FAIL() << missing;
    else
      GTEST_SKIP() << missing;
  }
};

TEST_F(LazPerf, DecodesEverySharedFileConvertedToLaz) {
  POINTRAST_REQUIRE_DATA();
  iotest::TempDir dir;
  int checked = 0;
  for (const char* folder : {"las", "laz"}) {
    for (const auto& entry : std::filesystem::directory_iterator(iotest::data(folder))) {
      const std::filesystem::path in = entry.path();
      const std::string ext = in.extension().string();
      if (ext != ".las" && ext != ".laz") continue;
      if (in.filename().string().find("laszip-compressor-version-1") != std::string::npos) continue;
      SCOPED_TRACE(in.string());
      const auto out = dir / (in.stem().string() + ".laz");
      convertLasFile(in, out);
      detail::InputFile file(out);
      const detail::LasHeader hd = detail::readLasHeader(file, true);
      EXPECT_EQ(lazPerfRecords(out), expected(inputRecords(in), hd.recordLength));
      ++checked;
    }
  }
  EXPECT_GE(checked, 18);
}

TEST_F(LazPerf, DecodesRandomRecordsOfEveryFormat) {
  iotest::TempDir dir;
  for (int format : {0, 1, 2, 3, 6, 7, 8}) {
    for (uint16_t extra : {uint16_t(0), uint16_t(3)}) {
      const uint16_t rl = uint16_t(las::kRecordSize[size_t(format)] + extra);
      const uint64_t n = 12345;
      const std::vector<uint8_t> records = iotest::randomRecords(format, rl, n, uint32_t(format * 7 + extra));
      for (uint32_t chunkSize : {uint32_t(1000), kVariableChunkSize}) {
        LasFileSetup setup;
        setup.header.assign(las::kHeaderSize14, 0);
        std::memcpy(setup.header.data(), "LASF", 4);
        setup.header[las::kVersionMajor] = 1;
        setup.header[las::kVersionMinor] = format >= 6 ? 4 : 2;
        setup.header.resize(format >= 6 ? las::kHeaderSize14 : las::kHeaderSize12);
        storeLE<uint16_t>(setup.header.data() + las::kHeaderSizeField, uint16_t(setup.header.size()));
        for (int a = 0; a < 3; ++a)
          storeLE<double>(setup.header.data() + las::kScale + 8 * a, 0.001);
        setup.pointFormat = format;
        setup.recordLength = rl;
        setup.laz = true;
        setup.chunkSize = chunkSize;
        const auto out = dir / ("pf" + std::to_string(format) + "-" + std::to_string(extra) + "-" +
                                std::to_string(chunkSize) + ".laz");
        LasFileWriter writer(out, setup);
        for (uint64_t at = 0, k = 1; at < n; ++k) {
          const uint64_t count = std::min<uint64_t>(k * 211, n - at);
          writer.writeChunk(records.data() + at * rl, count);
          at += count;
        }
        writer.commit();
        EXPECT_EQ(lazPerfRecords(out), expected(records, rl)) << out;
      }
    }
  }
}

} // namespace

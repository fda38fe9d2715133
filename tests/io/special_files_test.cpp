// Inputs that are not what a reader expects before it reads a byte: named pipes and other non-regular
// files, header counts read without the points (to refuse a file too large for the device before reading
// it), and the decompression command suggested for compressed files.
#include <chrono>
#include <fcntl.h>
#include <future>
#include <sys/stat.h>
#include <unistd.h>

#include "io/format_table.h"
#include "io/formats.h"
#include "io/io_test_util.h"
#include "io/las/las_format.h"

using pointrast::InputError;
using namespace pointrast::io;
using iotest::data;

namespace {

// The InputError message of fn, or "" when it does not throw one.
template <class Fn> std::string refusal(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A LAS 1.4 header whose 64-bit count states `points` records of 30 B, in a sparse file of the size those
// records take: the reader's check of the count against the file's size passes, and nothing but the header
// occupies the disk. False where the file system cannot hold a file that large.
bool writeSparseLas(const std::filesystem::path& path, uint64_t points) {
  auto bytes = iotest::readBytes(data("las/test1_4.las")); // LAS 1.4, point format 6 (30 B)
  uint32_t pointOffset = 0;
  std::memcpy(&pointOffset, bytes.data() + 96, 4);
  bytes.resize(pointOffset);
  const uint32_t legacy = 0;
  std::memcpy(bytes.data() + 107, &legacy, 4);
  std::memcpy(bytes.data() + 247, &points, 8);
  iotest::writeBytes(path, bytes);
  std::error_code ec;
  std::filesystem::resize_file(path, pointOffset + points * 30, ec);
  return !ec;
}

} // namespace

TEST(SpecialFiles, NamedPipeIsRefusedWithoutWaitingForAWriter) {
  iotest::TempDir dir;
  const auto pipe = dir / "pipe.las";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  for (auto call : {+[](const std::filesystem::path& p) { readCloud(p, iotest::quiet()); },
                    +[](const std::filesystem::path& p) { probeFile(p); },
                    +[](const std::filesystem::path& p) { detectFormat(p); },
                    +[](const std::filesystem::path& p) { statedPointCount(p); }}) {
    auto message = std::async(std::launch::async, [&] { return refusal([&] { call(pipe); }); });
    // A reader blocked in open() waits for a writer: be that writer (open and close at once) until the
    // call returns, so that a regression fails here instead of hanging the test binary.
    bool blocked = false;
    while (message.wait_for(std::chrono::seconds(blocked ? 0 : 10)) != std::future_status::ready) {
      blocked = true;
      int fd = ::open(pipe.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) ::close(fd);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    EXPECT_FALSE(blocked) << "opening a named pipe waited for a writer";
    const std::string m = message.get();
    EXPECT_NE(m.find("pipe.las: is a named pipe (FIFO), not a regular file"), std::string::npos) << m;
  }
}

TEST(SpecialFiles, DirectoriesAndDevicesAreNamedForWhatTheyAre) {
  iotest::TempDir dir;
  EXPECT_NE(refusal([&] { readCloud(dir.path(), iotest::quiet()); }).find("a folder, not a point cloud file"),
            std::string::npos);
  EXPECT_NE(refusal([] { probeFile("/dev/null"); }).find("/dev/null: is a character device"),
            std::string::npos);
}

TEST(SpecialFiles, StatedCountComesFromTheHeaderAlone) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  // 100 G points of 30 B: 3 TB that are never read (the call must return at once, with the header's count).
  iotest::TempDir dir;
  const auto huge = dir / "huge.las";
  if (!writeSparseLas(huge, 100'000'000'000ull))
    GTEST_SKIP() << "the temp file system holds no 3 TB sparse file";
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(statedPointCount(huge), 100'000'000'000ull);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));

  EXPECT_EQ(statedPointCount(data("las/autzen_trim.las")), 110000u);
  EXPECT_EQ(statedPointCount(data("las/no-points.las")), 0u);
  EXPECT_EQ(statedPointCount(data("ply/simple_binary.ply")),
            probeFile(data("ply/simple_binary.ply")).pointCount);
  EXPECT_EQ(statedPointCount(data("ply/simple_text.ply")), probeFile(data("ply/simple_text.ply")).pointCount);
  EXPECT_EQ(statedPointCount(data("xyz/data.xyz")), std::nullopt); // text: only reading counts
}

TEST(SpecialFiles, StatedCountIgnoresCountsTheFileCannotHold) {
  POINTRAST_REQUIRE_DATA("las/1.2-with-color.las");
  iotest::TempDir dir;
  // A PLY count larger than the data: no stated count (the reader names the lie when it meets the end).
  iotest::writeText(dir / "lie.ply", "ply\nformat ascii 1.0\nelement vertex 1000\nproperty float x\n"
                                     "property float y\nproperty float z\nend_header\n1 2 3\n");
  EXPECT_EQ(statedPointCount(dir / "lie.ply"), std::nullopt);
  iotest::writeText(dir / "ok.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                                    "property float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n");
  EXPECT_EQ(statedPointCount(dir / "ok.ply"), 2u);
  // LAS counts beyond the file are refused as the readers refuse them.
  auto las = iotest::readBytes(data("las/1.2-with-color.las"));
  const uint32_t lie = 0xFFFFFFFFu;
  std::memcpy(las.data() + 107, &lie, 4);
  iotest::writeBytes(dir / "lie.las", las);
  EXPECT_NE(refusal([&] { statedPointCount(dir / "lie.las"); }).find("header claims"), std::string::npos);
  // Compressed files state their header's count, without decoding a chunk.
  EXPECT_EQ(statedPointCount(data("laz/autzen_trim.laz")), 110000u);
  // Files the readers refuse are refused the same way.
  EXPECT_THROW(statedPointCount(dir / "missing.las"), InputError);
  EXPECT_THROW(statedPointCount(data("mmpld/test_xyz_float_none.mmpld")), InputError);
}

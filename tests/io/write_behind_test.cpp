// Write-behind of octree.bin: ranges reported in any order from several threads, windows handed to
// writeback only once every byte before them is written, and the file's bytes those written.
#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <random>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "io/io_test_util.h"
#include "io/write_behind.h"

namespace pointrast {
namespace {

using io::detail::WriteBehind;

constexpr uint64_t kWindow = uint64_t(1) << 20;

std::vector<uint8_t> fileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(WriteBehind, AWindowStartsOnlyOnceEveryByteBeforeItIsWritten) {
  iotest::TempDir dir;
  const int fd = ::open((dir / "a.bin").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  WriteBehind behind(fd, kWindow);
  // The second half of three windows first: nothing is complete from offset 0.
  behind.written(kWindow, 2 * kWindow);
  EXPECT_EQ(behind.flushedBytes(), 0u);
  behind.written(0, kWindow);
  // finish() hands whatever is complete to writeback.
  EXPECT_EQ(behind.finish(), 0);
  EXPECT_EQ(behind.flushedBytes(), 3 * kWindow);
  ::close(fd);
}

TEST(WriteBehind, RangesFromManyThreadsInAnyOrderKeepTheFileAsWritten) {
  iotest::TempDir dir;
  const std::filesystem::path path = dir / "b.bin";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  ASSERT_GE(fd, 0);
  // Ranges of uneven sizes covering 5.5 windows, written by four threads in a shuffled order.
  std::mt19937 rng(7);
  std::vector<std::pair<uint64_t, uint64_t>> ranges;
  const uint64_t total = kWindow * 11 / 2;
  for (uint64_t at = 0; at < total;) {
    const uint64_t n = std::min<uint64_t>(total - at, 1 + rng() % 100000);
    ranges.push_back({at, n});
    at += n;
  }
  std::vector<uint8_t> expected(total);
  for (size_t i = 0; i < total; ++i)
    expected[i] = uint8_t(i * 131 + (i >> 9));
  std::shuffle(ranges.begin(), ranges.end(), rng);
  {
    WriteBehind behind(fd, kWindow);
    std::vector<std::thread> writers;
    for (size_t t = 0; t < 4; ++t)
      writers.emplace_back([&, t] {
        for (size_t i = t; i < ranges.size(); i += 4) {
          const auto [at, n] = ranges[i];
          ASSERT_EQ(::pwrite(fd, expected.data() + at, n, off_t(at)), ssize_t(n));
          behind.written(at, n);
        }
      });
    for (std::thread& w : writers)
      w.join();
    EXPECT_EQ(behind.finish(), 0);
    EXPECT_EQ(behind.flushedBytes(), total);
  }
  ::close(fd);
  EXPECT_EQ(fileBytes(path), expected);
}

} // namespace
} // namespace pointrast

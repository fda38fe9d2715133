// Temporary names of writers: "<path>.partial-<pid>", renamed into place at commit, and what a killed
// process left under such a name removed by the next writer of the same path (never another live
// process's).
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "io/io_test_util.h"
#include "io/io_util.h"
#include "io/stale_partials.h"

namespace pointrast {
namespace {

namespace fs = std::filesystem;
using io::detail::PartialFile;

// The pid of a process that ran and was reaped: no process has it now.
pid_t deadPid() {
  pid_t pid = fork();
  if (pid == 0) _exit(0);
  int status = 0;
  waitpid(pid, &status, 0);
  return pid;
}

TEST(PartialFile, TheTemporaryNameCarriesThePid) {
  iotest::TempDir dir;
  const fs::path target = dir / "x.las";
  EXPECT_EQ(io::detail::partialPath(target).string(),
            target.string() + ".partial-" + std::to_string(getpid()));
  {
    PartialFile out(target);
    EXPECT_TRUE(fs::exists(io::detail::partialPath(target)));
    out.write("abc", 3);
    out.commit();
  }
  EXPECT_EQ(fs::file_size(target), 3u);
  EXPECT_FALSE(fs::exists(io::detail::partialPath(target)));
}

TEST(PartialFile, AWriterRemovesWhatKilledWritersLeft) {
  iotest::TempDir dir;
  const fs::path target = dir / "x.png";
  const std::string dead = std::to_string(deadPid()), deadToo = std::to_string(deadPid());
  // A file and a folder (an octree's) of dead processes; one of a live process (this test's parent); and
  // names that only look alike.
  iotest::writeText(dir / ("x.png.partial-" + dead), "half");
  fs::create_directories(dir / ("x.png.partial-" + deadToo) / "chunks");
  iotest::writeText(dir / ("x.png.partial-" + std::to_string(getppid())), "busy");
  iotest::writeText(dir / "x.png.partial-abc", "not a pid");
  iotest::writeText(dir / ("y.png.partial-" + dead), "another target");
  {
    PartialFile out(target);
    out.write("png", 3);
  } // not committed: its own partial file goes too
  EXPECT_FALSE(fs::exists(dir / ("x.png.partial-" + dead)));
  EXPECT_FALSE(fs::exists(dir / ("x.png.partial-" + deadToo)));
  EXPECT_TRUE(fs::exists(dir / ("x.png.partial-" + std::to_string(getppid()))));
  EXPECT_TRUE(fs::exists(dir / "x.png.partial-abc"));
  EXPECT_TRUE(fs::exists(dir / ("y.png.partial-" + dead)));
  EXPECT_FALSE(fs::exists(io::detail::partialPath(target)));
  EXPECT_FALSE(fs::exists(target));
}

} // namespace
} // namespace pointrast

// A writer killed at any moment leaves its output absent or complete, never half of it, and the next run
// needs no cleanup by hand; a full disk (a file-size limit) gives one line and no output. `lod` (a Potree
// folder) and `convert` (a LAS file) are each killed with SIGKILL at ten moments drawn from a fixed seed
// over the time a whole run takes.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::cliTempDir;
using pointrast::test::pointrastBinary;
using pointrast::test::slurp;

struct ChildRun {
  bool exited = false; // ended by itself (else killed)
  int exitCode = -1;
  std::string err;
  double seconds = 0;
};

struct RunOptions {
  double killAfter = -1;  // seconds; < 0: never
  rlim_t fileSizeLimit = 0; // bytes; 0: none
};

// The pointrast binary with `args`, straight from fork/exec (no shell in between to take the signal).
ChildRun runPointrastChild(const std::vector<std::string>& args, const RunOptions& options = {}) {
  const fs::path errFile = cliTempDir() / "crash_stderr.txt";
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    if (options.fileSizeLimit > 0) {
      rlimit limit{options.fileSizeLimit, options.fileSizeLimit};
      setrlimit(RLIMIT_FSIZE, &limit);
      signal(SIGXFSZ, SIG_IGN); // a write past the limit then fails with EFBIG, as on a full disk
    }
    int null = open("/dev/null", O_WRONLY);
    int err = open(errFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(null, STDOUT_FILENO);
    dup2(err, STDERR_FILENO);
    std::vector<char*> argv;
    std::string binary = pointrastBinary();
    argv.push_back(binary.data());
    std::vector<std::string> copy = args;
    for (std::string& a : copy)
      argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(binary.c_str(), argv.data());
    _exit(127);
  }
  ChildRun r;
  if (pid < 0) return r;
  int status = 0;
  const auto deadline = start + std::chrono::duration<double>(options.killAfter);
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (options.killAfter >= 0 && std::chrono::steady_clock::now() >= deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.exited = WIFEXITED(status);
  r.exitCode = r.exited ? WEXITSTATUS(status) : -1;
  r.err = slurp(errFile);
  return r;
}

std::string bytesOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Whether `a` and `b` (files, or folders of files) hold the same names and bytes.
bool sameOutput(const fs::path& a, const fs::path& b) {
  if (fs::is_regular_file(a)) return fs::is_regular_file(b) && bytesOf(a) == bytesOf(b);
  if (!fs::is_directory(a) || !fs::is_directory(b)) return false;
  std::vector<std::string> names, others;
  for (const auto& e : fs::directory_iterator(a))
    names.push_back(e.path().filename().string());
  for (const auto& e : fs::directory_iterator(b))
    others.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  std::sort(others.begin(), others.end());
  if (names != others) return false;
  for (const std::string& n : names)
    if (!sameOutput(a / n, b / n)) return false;
  return true;
}

size_t partialsIn(const fs::path& dir) {
  size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    n += e.path().filename().string().find(".partial-") != std::string::npos;
  return n;
}

fs::path fresh(const std::string& name) {
  const fs::path dir = cliTempDir() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// `command` builds `output` from autzen_trim: a reference run first, then ten runs killed at seeded
// moments; each leaves the output absent or equal to the reference. A complete one is removed (as its
// user would to build it again); the run after the last kill must succeed with nothing cleaned by hand.
void killAtRandomMoments(const std::string& name,
                         const std::function<std::vector<std::string>(const fs::path&)>& command,
                         const std::string& outputName) {
  const fs::path dir = fresh("crash_" + name);
  // The reference under the same name (an octree's metadata.json holds its folder's name).
  fs::create_directories(dir / "reference");
  const fs::path reference = dir / "reference" / outputName, output = dir / outputName;
  const ChildRun whole = runPointrastChild(command(reference));
  ASSERT_TRUE(whole.exited && whole.exitCode == 0) << whole.err;
  ASSERT_TRUE(fs::exists(reference));
  std::mt19937 random(20240611);
  std::uniform_real_distribution<double> moment(0.0, whole.seconds);
  int complete = 0, absent = 0;
  for (int i = 0; i < 10; ++i) {
    RunOptions options;
    options.killAfter = moment(random);
    const ChildRun killed = runPointrastChild(command(output), options);
    if (killed.exited) {
      EXPECT_EQ(killed.exitCode, 0) << killed.err;
    }
    if (fs::exists(output)) {
      EXPECT_TRUE(sameOutput(output, reference)) << name << ": killed after " << options.killAfter << " s";
      fs::remove_all(output);
      complete++;
    } else {
      absent++;
    }
  }
  std::printf("%s: %d runs killed before the end, %d complete\n", name.c_str(), absent, complete);
  const ChildRun next = runPointrastChild(command(output));
  ASSERT_TRUE(next.exited) << name;
  EXPECT_EQ(next.exitCode, 0) << next.err;
  EXPECT_TRUE(sameOutput(output, reference)) << name;
  EXPECT_EQ(partialsIn(dir), 0u) << name << ": the killed runs' temporaries are still there";
}

TEST(CrashSafetyCli, LodKilledAtRandomMomentsLeavesNoHalfOctree) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::string input = (pointrast::test::dataDir() / "las" / "autzen_trim.las").string();
  killAtRandomMoments(
      "lod", [&](const fs::path& out) { return std::vector<std::string>{"lod", input, "-o", out.string(), "-q"}; },
      "octree");
}

TEST(CrashSafetyCli, ConvertKilledAtRandomMomentsLeavesNoHalfFile) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::string input = (pointrast::test::dataDir() / "las" / "autzen_trim.las").string();
  killAtRandomMoments(
      "convert",
      [&](const fs::path& out) { return std::vector<std::string>{"convert", input, out.string(), "-q"}; },
      "out.las");
}

// A file-size limit below the output's size: the write fails as on a full disk. One line, exit 1, nothing
// left under the output's name or a temporary one.
TEST(CrashSafetyCli, AFullDiskGivesOneLineAndNoOutput) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const std::string input = (pointrast::test::dataDir() / "las" / "autzen_trim.las").string();
  const fs::path dir = fresh("crash_full");
  RunOptions options;
  options.fileSizeLimit = 256 * 1024; // the LAS is 3.7 MB, the octree's octree.bin 2.6 MB
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"convert", input, (dir / "out.las").string(), "-q"},
        std::vector<std::string>{"lod", input, "-o", (dir / "octree").string(), "-q"}}) {
    const ChildRun r = runPointrastChild(args, options);
    EXPECT_TRUE(r.exited) << args[0] << " was killed (SIGXFSZ?)";
    EXPECT_EQ(r.exitCode, 1) << args[0] << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("File too large"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_empty(dir)) << args[0] << " left something in " << dir;
  }
}

} // namespace

// `pointrast lod` as a user meets it: a JSON summary with every phase, the same folder bytes from one
// and two threads and out of core, one-line errors with exit 1 and nothing written, Ctrl-C leaving
// nothing behind, and the octree readable by `info` and `convert`.
#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include "cli_harness.h"
#include "test_data.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::runPointrast;

const fs::path kAutzen = pointrast::test::dataDir() / "las" / "autzen_trim.las";

fs::path fresh(const std::string& name) {
  fs::path p = pointrast::test::cliTempDir() / name;
  fs::remove_all(p);
  return p;
}

std::string bytesOf(const fs::path& p) {
  return pointrast::test::slurp(p);
}

bool onlyEntry(const fs::path& dir, const std::string& name) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename() != name) {
      ADD_FAILURE() << "left behind: " << e.path();
      return false;
    }
  return true;
}

TEST(LodBuildCli, JsonSummaryHasEveryPhase) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const fs::path out = fresh("lod_json");
  const auto r = runPointrast("lod " + kAutzen.string() + " -o " + out.string() + " --json --leaf-points 5k");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["points"], 110000);
  EXPECT_GT(j["nodes"].get<int>(), 4);
  EXPECT_GE(j["levels"].get<int>(), 3);
  EXPECT_EQ(j["bytes"].get<uint64_t>(), fs::file_size(out / "octree.bin") +
                                            fs::file_size(out / "hierarchy.bin") +
                                            fs::file_size(out / "metadata.json"));
  EXPECT_GT(j["points_per_second"].get<double>(), 0);
  std::vector<std::string> names;
  for (const auto& p : j["phases"]) {
    names.push_back(p["name"]);
    EXPECT_GE(p["seconds"].get<double>(), 0);
    EXPECT_TRUE(p.contains("points_per_second") && p.contains("cpu_seconds"));
  }
  EXPECT_EQ(names,
            (std::vector<std::string>{"read", "count", "chunk", "distribute", "index", "write", "commit"}));
  EXPECT_TRUE(r.err.empty()) << r.err; // --json: no progress or summary lines

  const auto info = runPointrast("info " + out.string());
  EXPECT_EQ(info.exitCode, 0) << info.err;
  EXPECT_NE(info.out.find("110000"), std::string::npos) << info.out;
}

TEST(LodBuildCli, SameBytesFromOneAndTwoThreadsAndWithLittleMemory) {
  const fs::path terrain = fresh("lod_terrain.las");
  ASSERT_EQ(runPointrast("generate terrain --points 300k -q -o " + terrain.string()).exitCode, 0);
  const fs::path a = fresh("lod_a"), b = fresh("lod_b"), c = fresh("lod_c");
  fs::create_directories(a);
  fs::create_directories(b);
  fs::create_directories(c);
  const std::string common = " --leaf-points 5k -q ";
  ASSERT_EQ(
      runPointrast("lod " + terrain.string() + common + "--threads 1 -o " + (a / "o").string()).exitCode, 0);
  ASSERT_EQ(
      runPointrast("lod " + terrain.string() + common + "--threads 2 -o " + (b / "o").string()).exitCode, 0);
  const auto spilled =
      runPointrast("lod " + terrain.string() + common + "--memory 2M --json -o " + (c / "o").string());
  ASSERT_EQ(spilled.exitCode, 0) << spilled.err;
  EXPECT_TRUE(nlohmann::json::parse(spilled.out)["out_of_core"].get<bool>());
  for (const char* file : {"octree.bin", "hierarchy.bin", "metadata.json"}) {
    EXPECT_EQ(bytesOf(a / "o" / file), bytesOf(b / "o" / file)) << file;
    EXPECT_EQ(bytesOf(a / "o" / file), bytesOf(c / "o" / file)) << file;
  }
  EXPECT_TRUE(onlyEntry(c, "o"));
  // Every point comes back out of the octree.
  const fs::path back = fresh("lod_back.las");
  const auto convert = runPointrast("convert " + (a / "o").string() + " " + back.string() + " -q");
  ASSERT_EQ(convert.exitCode, 0) << convert.err;
  const auto info = runPointrast("info " + back.string() + " --json");
  EXPECT_EQ(nlohmann::json::parse(info.out)["points"], 300000) << info.out;
}

// The index phase on the Vulkan device (lavapipe here) writes the CPU's bytes: a real scan in memory as
// Potree and as COPC, and generated terrain out of core; the JSON says the device took the chunks.
TEST(LodBuildCli, GpuIndexWritesTheSameBytes) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const fs::path terrain = fresh("lod_gpu_terrain.las");
  ASSERT_EQ(runPointrast("generate terrain --points 60k -q -o " + terrain.string()).exitCode, 0);
  struct Case {
    fs::path input;
    std::string name, options;
    bool outOfCore;
  };
  const Case cases[] = {{kAutzen, "o", " --leaf-points 5k", false},
                        {kAutzen, "o.copc.laz", " --leaf-points 5k", false},
                        {terrain, "o", " --leaf-points 2k --memory 2M", true}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.input.string() + c.options + " -o " + c.name);
    const fs::path cpu = fresh("lod_index_cpu"), gpu = fresh("lod_index_gpu");
    fs::create_directories(cpu);
    fs::create_directories(gpu);
    const auto onCpu =
        runPointrast("lod " + c.input.string() + c.options + " --json -o " + (cpu / c.name).string());
    ASSERT_EQ(onCpu.exitCode, 0) << onCpu.err;
    const auto onGpu = runPointrast("lod " + c.input.string() + c.options + " --json --index-on gpu -o " +
                                    (gpu / c.name).string());
    ASSERT_EQ(onGpu.exitCode, 0) << onGpu.err;
    EXPECT_EQ(onGpu.err.find("Validation"), std::string::npos) << onGpu.err;
    const nlohmann::json j = nlohmann::json::parse(onGpu.out);
    EXPECT_EQ(j["index_on"], "gpu");
    EXPECT_GT(j["index_gpu_chunks"].get<int>(), 0);
    EXPECT_EQ(j["index_cpu_chunks"].get<int>(), 0);
    EXPECT_EQ(j["out_of_core"].get<bool>(), c.outOfCore);
    EXPECT_EQ(nlohmann::json::parse(onCpu.out)["index_on"], "cpu");
    if (fs::is_directory(cpu / c.name)) {
      for (const char* file : {"octree.bin", "hierarchy.bin"})
        EXPECT_EQ(bytesOf(gpu / c.name / file), bytesOf(cpu / c.name / file)) << file;
      EXPECT_EQ(fs::file_size(gpu / c.name / "metadata.json"), fs::file_size(cpu / c.name / "metadata.json"));
    } else {
      EXPECT_EQ(bytesOf(gpu / c.name), bytesOf(cpu / c.name));
    }
  }
  const auto wrong =
      runPointrast("lod " + terrain.string() + " --index-on tpu -o " + fresh("lod_tpu").string());
  EXPECT_EQ(wrong.exitCode, 1);
  EXPECT_NE(wrong.err.find("--index-on expects cpu or gpu"), std::string::npos) << wrong.err;
  EXPECT_FALSE(fs::exists(fresh("lod_tpu")));
}

TEST(LodBuildCli, MistakesGiveOneLineAndWriteNothing) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const fs::path dir = fresh("lod_errors");
  fs::create_directories(dir / "exists");
  std::ofstream(dir / "exists" / "file") << "a file, not a folder";
  const std::string out = " -o " + (dir / "o").string();
  const std::string cases[] = {
      "lod " + (dir / "missing.las").string() + out,
      "lod " + kAutzen.string() + " -o " + (dir / "exists").string(),
      "lod " + kAutzen.string() + out + " --memory lots",
      "lod " + kAutzen.string() + out + " --encoding zip",
      "lod " + kAutzen.string() + out + " --color-filter median",
      "lod " + kAutzen.string() + out + " --leaf-points 0",
      "lod " + kAutzen.string() + out + " --spacing -1",
      "lod " + kAutzen.string() + out + " --spacing nan",
      "lod " + kAutzen.string() + out + " --spacing inf",
      "lod " + (pointrast::test::dataDir() / "las" / "no-points.las").string() + out,
      "lod " + (pointrast::test::dataDir() / "mmpld" / "test_xyz_float_none.mmpld").string() + out,
      "lod " + kAutzen.string(),
      "lod " + kAutzen.string() + " -o ''",
      "lod " + kAutzen.string() + " -o " + (dir / "exists").string() + "/",
      "lod " + kAutzen.string() + " -o " + (dir / "exists" / "file" / "sub").string(),
  };
  for (const std::string& args : cases) {
    const auto r = runPointrast(args);
    EXPECT_FALSE(r.signaled) << args;
    EXPECT_EQ(r.exitCode, 1) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_TRUE(onlyEntry(dir, "exists")) << args;
  }
  // Each names what is wrong with the output's name.
  const auto file =
      runPointrast("lod " + kAutzen.string() + " -o " + (dir / "exists" / "file" / "sub").string());
  EXPECT_NE(file.err.find("is a file, not a folder"), std::string::npos) << file.err;
  const auto slash = runPointrast("lod " + kAutzen.string() + " -o " + (dir / "exists").string() + "/");
  EXPECT_NE(slash.err.find("exists: already exists"), std::string::npos) << slash.err;
}

// What a build killed outright (SIGKILL, a second Ctrl-C, a file-size limit) left, the next build of the
// same folder removes: a folder named for a pid no process has.
TEST(LodBuildCli, TheNextBuildRemovesWhatAKilledOneLeft) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const fs::path dir = fresh("lod_stale");
  fs::create_directories(dir);
  const pid_t dead = fork();
  ASSERT_GE(dead, 0);
  if (dead == 0) _exit(0);
  waitpid(dead, nullptr, 0);
  const fs::path stale = dir / ("o.partial-" + std::to_string(dead));
  fs::create_directories(stale / "chunks");
  std::ofstream(stale / "octree.bin") << "half an octree";
  const auto r = runPointrast("lod " + kAutzen.string() + " -o " + (dir / "o").string() + " -q");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(onlyEntry(dir, "o"));
}

TEST(LodBuildCli, InterruptLeavesNothingBehind) {
  const fs::path dir = fresh("lod_interrupt");
  fs::create_directories(dir);
  const fs::path input = dir / "t.las";
  ASSERT_EQ(runPointrast("generate terrain --points 3M -q -o " + input.string()).exitCode, 0);
  // Out of core on one thread: long enough to be interrupted while temporary chunk files exist.
  const std::string command = pointrast::test::pointrastBinary() + " lod " + input.string() + " -o " +
                              (dir / "o").string() + " --threads 1 --memory 4M -q";
  const fs::path errors = pointrast::test::cliTempDir() / "lod_interrupt_stderr.txt";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    // Held once its chunk files are written (until interrupted), so that the signal lands mid-build
    // whatever the machine's load.
    setenv("POINTRAST_TEST_HOLD", "chunks-written", 1);
    execl("/bin/sh", "sh", "-c", ("exec " + command + " 2>" + errors.string()).c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // Interrupted once the build has written something beside the input (its temporary folder); held at its
  // chunk files, it cannot end before the signal. The bound only fails a build that never starts writing.
  int status = 0;
  bool exited = false, writing = false;
  for (int polls = 0; polls < 60'000 && !writing && !exited; ++polls) {
    for (const auto& e : fs::directory_iterator(dir))
      writing = writing || e.path().filename() != "t.las";
    exited = waitpid(pid, &status, WNOHANG) == pid;
    if (!writing && !exited) usleep(2'000);
  }
  if (!exited) {
    kill(pid, SIGINT);
    waitpid(pid, &status, 0);
  }
  ASSERT_TRUE(writing) << "the build wrote nothing before it ended";
  ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << WTERMSIG(status) << ": "
                                 << pointrast::test::slurp(errors);
  EXPECT_EQ(WEXITSTATUS(status), 130) << "the build was not interrupted";
  fs::remove(input);
  for (const auto& e : fs::directory_iterator(dir))
    ADD_FAILURE() << "left behind: " << e.path();
}

} // namespace

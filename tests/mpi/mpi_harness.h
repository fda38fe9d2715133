// What the distributed tests share: skipping a build without MPI, mpirun's command line (lavapipe, the
// validation layer, oversubscribed cores, run as root in CI), a whole job run with a time bound, and the
// composited words rank 0 writes.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "cli/cli_harness.h"
#include "mpi/mpi_job.h"

// Skips the test in a build without MPI (there is nothing distributed to test).
#define REQUIRE_MPI()                                                                                        \
  do {                                                                                                       \
    if (!pointrast::mpi::Job::built() || std::string(POINTRAST_MPIRUN).empty())                              \
      GTEST_SKIP() << "this build has no MPI (CMake option POINTRAST_MPI off, or no mpirun found)";          \
  } while (0)

namespace pointrast::test::mpi {

// An empty pixel's word.
constexpr uint64_t kEmpty = ~uint64_t(0);

// The environment every rank runs in, then mpirun with its options, oversubscribed.
inline std::string mpirunCommand(const std::string& env = "", const std::string& options = "") {
  return "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 "
         "POINTRAST_VALIDATION=${POINTRAST_VALIDATION:-1} XDG_RUNTIME_DIR=/tmp " +
         env + " " + POINTRAST_MPIRUN + " --oversubscribe " + options;
}

// mpirun with `ranks` ranks, to go before the binary; rank 0 writes its last frame's composited words to
// `words` when it is given.
inline std::string mpirun(uint32_t ranks, const std::filesystem::path& words = {}) {
  return mpirunCommand(words.empty() ? "" : "POINTRAST_MPI_WORDS='" + words.string() + "'",
                       "-np " + std::to_string(ranks));
}

// The words rank 0 wrote (none when it wrote nothing).
inline std::vector<uint64_t> readWords(const std::filesystem::path& path) {
  std::vector<uint64_t> words;
  if (!std::filesystem::exists(path)) return words;
  std::ifstream in(path, std::ios::binary);
  words.resize(std::filesystem::file_size(path) / 8);
  in.read(reinterpret_cast<char*>(words.data()), std::streamsize(words.size() * 8));
  return words;
}

struct MpiRun {
  int exitCode = -1;
  bool signaled = false;
  std::string out, err;
  double seconds = 0;
};

// Runs `mpirun --oversubscribe LAUNCH` (LAUNCH names the binary, e.g. "-np 2 " + bin + " render ..."), with
// `env` set for every rank, stopped after `timeout` seconds so that a hang fails the test.
inline MpiRun runMpi(const std::string& launch, const std::string& env = "", int timeout = 120) {
  const std::filesystem::path out = cliTempDir() / "mpi_stdout.txt", err = cliTempDir() / "mpi_stderr.txt";
  std::filesystem::remove(out);
  const std::string command = "timeout -k 5 " + std::to_string(timeout) + " " + mpirunCommand(env) + launch +
                              " >" + out.string() + " 2>" + err.string() + " </dev/null";
  const auto start = std::chrono::steady_clock::now();
  const int status = std::system(command.c_str());
  MpiRun r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.signaled = WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) > 128);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

} // namespace pointrast::test::mpi

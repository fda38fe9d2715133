// Running the pointrast binary from tests as a user would: stdout and stderr captured separately, the
// validation layer on unless POINTRAST_VALIDATION says otherwise.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include "test_data.h"

namespace pointrast::test {

struct CliResult {
  int exitCode = -1;
  bool signaled = false; // killed by a signal (a crash), or a shell exit status above 128
  std::string out, err;
};

// A folder of this test process under the system's temp directory.
inline std::filesystem::path cliTempDir() {
  static std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("pointrast_cli_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct CliOptions {
  // > 0: the command is stopped after this many seconds (exit code 124), so a hang fails its test
  // instead of stalling the suite.
  int timeoutSeconds = 0;
  // Where stdout goes instead of being captured (e.g. /dev/full); out is then empty.
  std::string stdoutPath;
};

inline CliResult runPointrast(const std::string& args, const CliOptions& options = {}) {
  auto out = cliTempDir() / "stdout.txt", err = cliTempDir() / "stderr.txt";
  std::filesystem::remove(out);
  std::string prefix = options.timeoutSeconds > 0
                           ? "timeout -k 5 " + std::to_string(options.timeoutSeconds) + " env "
                           : std::string();
  std::string command = prefix + "POINTRAST_VALIDATION=${POINTRAST_VALIDATION:-1} XDG_RUNTIME_DIR=/tmp " +
                        pointrastBinary() + " " + args + " >" +
                        (options.stdoutPath.empty() ? out.string() : options.stdoutPath) + " 2>" +
                        err.string();
  int status = std::system(command.c_str());
  CliResult r;
  r.signaled = WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) > 128);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

} // namespace pointrast::test

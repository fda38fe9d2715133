// pointrast: render huge point clouds by software rasterization in compute shaders.
// Thin on purpose: parsing and wiring only; the work lives in src/.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "base/build_info.h"
#include "base/error.h"
#include "base/text.h"
#include "commands.h"
#include "gpu/vulkan_api.h"
#include "mpi/mpi_job.h"

namespace {

// The one error line: control characters escaped, so a file name holding a newline cannot split it. A rank
// of a distributed job tells the others instead, and rank 0 prints the line once for the job.
void printError(const std::string& message) {
  pointrast::mpi::Job& job = pointrast::mpi::Job::get();
  if (job.launched()) {
    job.fail(message);
    return;
  }
  std::fprintf(stderr, "pointrast: %s\n", pointrast::printableLine(message).c_str());
}

// What a command printed must have reached stdout (a full disk, /dev/full, a failing device): a lost
// write is an error like any other, exit 1 with one line, unless the command already failed and said so.
int checkStdout(int status) {
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  const int error = errno;
  if (flushed && !std::ferror(stdout)) return status;
  if (status == 0)
    printError(std::string("cannot write to standard output") +
               (error ? ": " + std::string(std::strerror(error)) : ""));
  return 1;
}

int runCommand(int argc, char** argv) {
  using namespace pointrast;
  CLI::App app{"pointrast: renders billions of points and particles by software rasterization in compute "
               "shaders (Vulkan 1.3; any GPU, or the CPU through lavapipe).\n\n"
               "Examples:\n"
               "  pointrast render -o demo.png                       # built-in demo scene\n"
               "  pointrast render cloud.las -o out.png --json       # a point cloud file, timing as JSON\n"
               "  pointrast info cloud.las                           # what a file holds\n"
               "  pointrast generate terrain --points 10M -o t.las   # a synthetic scene as LAS\n"
               "  pointrast convert in.ply out.las --order morton    # reorder and write LAS\n",
               "pointrast"};
  app.require_subcommand(1);
  app.fallthrough(false);
  app.set_version_flag("--version", std::string("pointrast 0.1.0 (") + buildCommit() + ")");
  app.footer("Run `pointrast COMMAND --help` for a command's options. Exit status: 0 success, 1 error.");

  const std::vector<app::RegisteredCommand> commands = app::addCommands(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string which = app.get_subcommands().empty() ? "" : " " + app.get_subcommands().front()->get_name();
    printError(std::string(e.what()) + " (see `pointrast" + which + " --help`)");
    return 1;
  }

  try {
    for (CLI::App* sub : app.get_subcommands()) {
      // Under mpirun with several ranks only render, view, serve and bench draw a share per rank; the others
      // would each do the whole work (and write the same files).
      const std::string name = sub->get_name();
      if (mpi::Job::get().distributed() && name != "render" && name != "view" && name != "serve" &&
          name != "bench")
        throw InputError(
            "`pointrast " + name +
            "` runs as one process; under mpirun only render, view, serve and bench divide their "
            "work among ranks (docs/mpi.md)");
      for (const app::RegisteredCommand& command : commands)
        if (command.subcommand == sub) return command.run();
    }
    return 1;
  } catch (const mpi::JobFailed&) {
    return 1; // another rank failed; rank 0 printed its line
  } catch (const InputError& e) {
    printError(e.what());
  } catch (const UnsupportedError& e) {
    printError(e.what());
  } catch (const DeviceFault& e) {
    printError(e.what());
  } catch (const gpu::VulkanError& e) {
    printError(e.what());
  } catch (const std::bad_alloc&) {
    printError("out of host memory");
  } catch (const std::filesystem::filesystem_error& e) {
    // The library's text ("filesystem error: status: ... [path]") as our line: the path, then the reason.
    printError((e.path1().empty() ? "" : e.path1().string() + ": ") + e.code().message());
  } catch (const std::exception& e) {
    printError(e.what());
  }
  return 1;
}

} // namespace

namespace pointrast::app {

std::vector<RegisteredCommand> addCommands(CLI::App& app) {
  std::vector<RegisteredCommand> commands;
  // Each add<Name> adds exactly one subcommand: the newest is the one it made.
  auto add = [&](Command (*addCommand)(CLI::App&)) {
    Command run = addCommand(app);
    const std::vector<CLI::App*> all = app.get_subcommands(std::function<bool(CLI::App*)>());
    commands.push_back({all.back(), std::move(run)});
  };
#define POINTRAST_COMMAND(Name) add(add##Name);
  POINTRAST_COMMAND_ROWS
#ifdef POINTRAST_TEST_COMMAND_ROWS
#include POINTRAST_TEST_COMMAND_ROWS
#endif
#undef POINTRAST_COMMAND
  return commands;
}

} // namespace pointrast::app

int main(int argc, char** argv) {
  // Under mpirun: MPI starts before anything else and ends after everything (src/mpi/mpi_job.h).
  pointrast::mpi::Job::start(argc, argv);
  const int status = checkStdout(runCommand(argc, argv));
  pointrast::mpi::Job::finish();
  return status;
}

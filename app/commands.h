// The subcommands of `pointrast`. Each registers its options on the CLI11 app and returns the function
// that runs it; main() turns exceptions into one line on stderr and exit code 1.
//
// A new command is its cmd_<name>.cpp, defining `Command add<Name>(CLI::App&)`, plus one row in
// POINTRAST_COMMAND_ROWS below: the row declares the function and places the command in `pointrast --help`.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "io/writer.h"

namespace CLI {
class App;
}

namespace pointrast::app {

using Command = std::function<int()>;

// Every command, in the order `pointrast --help` lists them; the test-only commands of tests/commands
// (CMake option POINTRAST_TEST_COMMANDS) follow, from their own rows.
#define POINTRAST_COMMAND_ROWS                                                                               \
  POINTRAST_COMMAND(Info)                                                                                    \
  POINTRAST_COMMAND(Render)                                                                                  \
  POINTRAST_COMMAND(Convert)                                                                                 \
  POINTRAST_COMMAND(Profile)                                                                                 \
  POINTRAST_COMMAND(Generate)                                                                                \
  POINTRAST_COMMAND(Bench)                                                                                   \
  POINTRAST_COMMAND(BenchIo)                                                                                 \
  POINTRAST_COMMAND(View)                                                                                    \
  POINTRAST_COMMAND(Lod)                                                                                     \
  POINTRAST_COMMAND(Serve)

#define POINTRAST_COMMAND(Name) Command add##Name(CLI::App& app);
POINTRAST_COMMAND_ROWS
#ifdef POINTRAST_TEST_COMMAND_ROWS
#include POINTRAST_TEST_COMMAND_ROWS
#endif
#undef POINTRAST_COMMAND

// Registers every command of the rows above on `app`; each entry pairs the subcommand CLI11 made with
// the function that runs it.
struct RegisteredCommand {
  CLI::App* subcommand;
  Command run;
};
std::vector<RegisteredCommand> addCommands(CLI::App& app);

// LAS 1.2 PF3, or 1.4 PF7 when the count needs 64-bit counts; InputError for a non-.las name.
io::LasFlavor lasFlavorFor(const std::string& output, uint64_t points);

} // namespace pointrast::app

// `pointrast test-echo` (test builds only, see command_rows.inc): prints its text, or refuses an empty one
// with one line and exit 1 like every command.
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "base/error.h"
#include "commands.h"

namespace pointrast::app {

Command addTestEcho(CLI::App& app) {
  auto text = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("test-echo", "Test build only: prints --text");
  cmd->add_option("--text", *text, "What to print")->required();
  return [text] {
    if (text->empty()) throw InputError("--text must not be empty");
    std::printf("%s\n", text->c_str());
    return 0;
  };
}

} // namespace pointrast::app

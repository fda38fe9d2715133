// The subcommands of `pointrast`. Each registers its options on the CLI11 app and returns the function
// that runs it; main() turns exceptions into one line on stderr and exit code 1.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "io/writer.h"

namespace CLI {
class App;
}

namespace pointrast::app {

using Command = std::function<int()>;

Command addInfo(CLI::App& app);
Command addRender(CLI::App& app);
Command addConvert(CLI::App& app);
Command addGenerate(CLI::App& app);
Command addBench(CLI::App& app);
Command addBenchIo(CLI::App& app);
Command addView(CLI::App& app);
Command addLod(CLI::App& app);
Command addServe(CLI::App& app);

// LAS 1.2 PF3, or 1.4 PF7 when the count needs 64-bit counts; InputError for a non-.las name.
io::LasFlavor lasFlavorFor(const std::string& output, uint64_t points);

} // namespace pointrast::app

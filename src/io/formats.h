// Per-format entry points that are private to src/io/ (reader.cpp dispatches to them).
#pragma once

#include <filesystem>

#include "io/reader.h"

namespace pointrast::io::detail {

FileInfo probeLas(const std::filesystem::path& path);
FileInfo probePly(const std::filesystem::path& path);
FileInfo probeXyz(const std::filesystem::path& path);

} // namespace pointrast::io::detail

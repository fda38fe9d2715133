// Per-format entry points that are private to src/io/ (the rows of format_table.cpp name them).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "io/reader.h"

namespace pointrast::io::detail {

FileInfo probeLas(const std::filesystem::path& path);
FileInfo probePly(const std::filesystem::path& path);
FileInfo probeXyz(const std::filesystem::path& path);
FileInfo probePotreeFolder(const std::filesystem::path& path);

// "not a LAS, LAZ, ... file (unrecognised content and extension)", naming every row.
std::string unrecognisedFormatText();

// The vertex count of a PLY header where the file's size can hold it (statedPointCount()).
std::optional<uint64_t> statedCountPly(const std::filesystem::path& path);

// Bytes of MMPLD particle data the reader reads and decodes at a time (default 32 MiB). Tests lower it to
// cross chunk boundaries with small files; 0 restores the default.
void setMmpldChunkBytes(uint64_t bytes);

} // namespace pointrast::io::detail

// Reading point clouds from files. Every reader treats its input as hostile: counts and sizes are
// checked against the file size before anything is allocated, NaN/Inf coordinates are dropped and
// counted, and a truncated or lying file throws InputError with one clear sentence naming the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cloud/cloud.h"

namespace pointrast::io {

struct FormatInfo; // io/format_table.h: the formats, their detection and what each can be read as

// Header-level facts for `pointrast info`, without reading every point where the format allows.
struct FileInfo {
  const FormatInfo* format = nullptr; // the row of io/format_table.h (set by probeFile)
  std::string formatDetail;           // "LAS 1.2, point format 3 (34 B records)", "PLY binary_little_endian"
  uint64_t pointCount = 0;            // as stated by the header (LAS/PLY) or counted (XYZ)
  Bounds bounds;                      // header bounds where the format has them, else computed
  bool boundsFromHeader = false;
  glm::dvec3 scale{0}, offset{0}; // formats that store quantized positions (LAS); zero for the others
  bool hasColor = false;
  int colorBits = 0; // 8 or 16 for LAS RGB (detected from the values), 8 for PLY uchar...
  std::vector<std::pair<std::string, std::string>> extra; // ordered (key, value) lines for display
};

struct ReadOptions {
  bool progress = true;       // progress line on stderr when it is a terminal
  bool keepAttributes = true; // intensity, classification, return number, point source id
};

// Reads the whole file into a PointCloud (bounds computed from the points), through the format's row of
// io/format_table.h. Throws InputError, for a format that cannot be read as a cloud too.
PointCloud readCloud(const std::filesystem::path& path, const ReadOptions& options = {});
FileInfo probeFile(const std::filesystem::path& path);
// The point count the file's header states, read without touching the points (probeFile() may read them
// all: LAS color depth, PLY bounds), so that a caller can refuse a file it has no room for before reading
// it. LAS, LAZ, COPC: the header's count; PLY: the vertex count. nullopt where only reading tells (XYZ
// text, a PLY count larger than the file holds, an octree folder). Throws InputError as probeFile() does.
std::optional<uint64_t> statedPointCount(const std::filesystem::path& path);

// Per format (the rows of io/format_table.h name these).
PointCloud readLas(const std::filesystem::path& path, const ReadOptions& options = {});
PointCloud readPly(const std::filesystem::path& path, const ReadOptions& options = {});
PointCloud readXyz(const std::filesystem::path& path, const ReadOptions& options = {});
// Every point of a Potree 2.0 octree (its folder or metadata.json), nodes decoded on all cores.
PointCloud readPotree(const std::filesystem::path& path, const ReadOptions& options = {});

} // namespace pointrast::io

// COPC (Cloud Optimized Point Cloud, copc.io, version 1.0): a LAZ 1.4 file (point formats 6-8) whose
// chunks are the nodes of an octree. The "copc" info VLR (record 1) gives the root cube and spacing and
// where the root hierarchy page is; hierarchy pages (in the "copc" EVLR, record 1000) list each node's
// chunk by voxel key, or point to the page that lists a subtree.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "cloud/octree.h"

namespace pointrast::io {

// Opens a COPC file as an LOD source: the root hierarchy page now, deeper pages when a node below them is
// first asked for, each node's points decoded on their own (a LAZ chunk). Thread-safe. Hostile
// hierarchies (cycles, entries outside the file or outside their page's subtree, keys out of range,
// counts that disagree with the chunk) throw InputError naming the file. Throws InputError for a file
// that is not COPC.
std::unique_ptr<lod::NodeSource> openCopc(const std::filesystem::path& path);

namespace detail {
class InputFile;
}

// Whether a LAS/LAZ file carries a COPC info VLR (by its VLR list, without reading the hierarchy).
// Tolerant: a damaged header is just not COPC.
bool looksLikeCopc(const std::filesystem::path& path);
bool hasCopcInfoVlr(const detail::InputFile& file);

// The generating software of the COPC files `pointrast lod` writes (copc_writer.h), which says how the
// inner nodes' colors were made: averages of the points each stands for, or the points' own colors.
inline constexpr const char* kCopcSoftwareAveraged = "pointrast lod, averaged colors";
inline constexpr const char* kCopcSoftwareExact = "pointrast lod";

// What `info` shows of a COPC file: the info VLR's cube and spacing, and the hierarchy walked in full
// (node count, depth, points in nodes).
struct CopcSummary {
  glm::dvec3 center{0.0};
  double halfSize = 0, spacing = 0;
  uint64_t rootPageOffset = 0, rootPageSize = 0;
  uint64_t nodes = 0, pages = 0, points = 0;
  int depth = 0;
  std::string colors; // how inner nodes' colors were made, for files pointrast wrote (else empty)
};
std::optional<CopcSummary> summarizeCopc(const std::filesystem::path& path);

} // namespace pointrast::io

// EPT (Entwine Point Tile, entwine.io, version 1.0): an octree as a folder. ept.json gives the root cube
// ("bounds"), the tight bounds, the point schema, "span" (the voxel resolution of every node) and how
// node data is stored ("laszip": a LAZ file per node, "binary": the schema's attributes point after
// point, "zstandard": the binary layout compressed with zstd); ept-hierarchy/0-0-0-0.json maps each
// node "D-X-Y-Z" to its point count, or to -1 where ept-hierarchy/D-X-Y-Z.json lists that subtree;
// ept-data/D-X-Y-Z.{laz,bin,zst} holds a node's points.
#pragma once

#include <filesystem>
#include <memory>

#include "cloud/octree.h"
#include "io/reader.h"

namespace pointrast::io {

// Opens an EPT dataset (its ept.json or its folder) as an LOD source: ept.json and the root hierarchy
// file now, subtree hierarchy files when a node below them is first asked for, each node's data file on
// its own. Thread-safe. Positions stay the schema's integers (scale/offset from the X/Y/Z entries; a
// float X/Y/Z schema is quantized to 2^31 steps of the root cube). Hostile datasets (malformed JSON,
// keys out of range or outside their file's subtree, cycles of hierarchy files, counts that disagree
// with the data) throw InputError with one sentence naming the file.
std::unique_ptr<lod::NodeSource> openEpt(const std::filesystem::path& path);

// Whether path is an EPT dataset: a file named ept.json, or a folder holding one.
bool looksLikeEpt(const std::filesystem::path& path);

// Every point of an EPT dataset as one cloud (nodes in depth-first order, decoded in parallel). Colors
// follow the LAS rule (16-bit when any value exceeds 255). Throws InputError.
PointCloud readEpt(const std::filesystem::path& path, const ReadOptions& options = {});

namespace detail {
// ept.json's facts; colors from the root node and its children (not every node: datasets are huge).
FileInfo probeEpt(const std::filesystem::path& path);
} // namespace detail

} // namespace pointrast::io

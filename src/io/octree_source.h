// The octrees the LOD methods stream from, whatever their format: every one serves nodes through
// lod::NodeSource (cloud/octree.h). Today a Potree 2.0 folder (ours or PotreeConverter's); COPC files and
// EPT datasets map onto the same interface (their D-X-Y-Z voxel keys are NodeKeys, their hierarchy pages
// and files are read on demand by children()).
#pragma once

#include <filesystem>
#include <memory>

#include "cloud/octree.h"

namespace pointrast::io {

// Whether `path` is an octree a LOD method can stream, by its files, without parsing.
bool looksLikeOctree(const std::filesystem::path& path);

// Opens it. Throws InputError naming the path for anything that is not an octree of a known format, and
// for a damaged one (as the format's reader finds it).
std::unique_ptr<lod::NodeSource> openOctree(const std::filesystem::path& path);

} // namespace pointrast::io

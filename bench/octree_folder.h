// The command line's octree provider for the suites that draw octrees (bench/octree_cache.h): a folder of
// octrees, one Potree 2.0 folder per key, built when missing with the octree builder (`pointrast lod`) on all
// cores from the points written to a temporary LAS file beside it (removed after the build; N points take
// 26 N bytes of LAS and 24 N of octree at once). The build's time and phases are kept in
// <dir>/<key>.build.json for the runs that reuse the octree.
#pragma once

#include <filesystem>

#include "bench/octree_cache.h"

namespace pointrast::bench {

OctreeProvider octreeFolder(const std::filesystem::path& dir, bool progress);

// $XDG_CACHE_HOME/pointrast/octrees, or ~/.cache/pointrast/octrees (the temporary folder's without a home).
std::filesystem::path defaultOctreeFolder();

} // namespace pointrast::bench

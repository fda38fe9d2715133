// Octrees of the benchmark's data sets, for the LOD methods: a Potree 2.0 folder per data set, built once
// from the data set's points with the octree builder and kept in a cache folder, so that later runs (and
// other suites) reuse it. The build's time is reported with the results.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "cloud/cloud.h"

namespace pointrast::bench {

struct DatasetOctree {
  std::filesystem::path path; // the folder
  bool reused = false;        // found in the cache, not built by this run
  double buildSeconds = 0;    // the build's wall time (when reused: as recorded when it was built)
  uint64_t points = 0;
  uint64_t bytes = 0; // the folder's files
  std::string phases; // the builder's phases and their seconds, one line
};

// The octree under the key `name` (which names the data set, its size and seed), built from `points()` when
// it is not at hand (a provider that finds it in a cache never asks for the points, which for a generated
// stand-in saves generating them). Throws InputError or UnsupportedError when it cannot be had.
using OctreeProvider =
    std::function<DatasetOctree(const std::string& name, const std::function<const PointCloud&()>& points)>;

// The octree cache the CLI uses: `dir`/KEY is the Potree 2.0 folder of the data set keyed KEY, `dir`/KEY.json
// what its build recorded (time, phases, threads) and the sizes of the folder's files. An entry is reused
// when both agree and the folder opens; a damaged one (a missing or unreadable record, a file of another
// size, a folder that does not open) is removed and rebuilt, with one note line; one that cannot be removed
// is refused with an InputError. Leftovers of builds that were killed are removed first. A build runs the
// octree builder's in-memory phases on all cores (io::buildPotree's, from the points instead of files) into
// a temporary folder renamed into place, after checking that the disk and the memory can hold it.
struct OctreeCacheOptions {
  std::filesystem::path dir;
  unsigned threads = 0;                           // 0: all hardware threads
  bool progress = true;                           // the builder's progress lines on a terminal
  std::function<void(const std::string&)> onNote; // one line each: a build, a damaged entry rebuilt
};
OctreeProvider octreeCache(OctreeCacheOptions options);

// $XDG_CACHE_HOME/pointrast/octrees, or ~/.cache/pointrast/octrees.
std::filesystem::path defaultOctreeCacheDir();

// Builds the octree of points in memory into the Potree 2.0 folder `dir` (which must not exist): phase
// "records" (the cloud as PointRecords), then the octree builder's in-memory phases and "commit". The
// result's path, points, bytes, buildSeconds and phases are filled in. Throws InputError (a full disk).
DatasetOctree buildCloudOctree(const PointCloud& cloud, const std::filesystem::path& dir, unsigned threads,
                               bool progress);

} // namespace pointrast::bench

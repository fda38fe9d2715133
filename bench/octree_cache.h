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

} // namespace pointrast::bench

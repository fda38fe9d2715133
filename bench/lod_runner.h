// The LOD methods in the benchmarks.
//
// In the point suites (paper2022's LOD columns of Table 1 and its Table 2 for octrees): the rows of the
// method table that read octrees are measured on the data set's octree (BenchConfig::octrees builds or finds
// it), from the same cameras as the other methods, each frame at full detail after its selection is
// resident (Renderer::render with an octree), with --min-node-px at its default of 100 as in the paper.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench/runner.h"
#include "cloud/octree.h"

namespace pointrast::bench {

// The cache key of a data set's octree: its name, size and seed (a file: its name and file name).
std::string octreeKey(const Dataset& dataset);

// A suite's data set as an octree: `octrees` finds it or builds it from the data set's points (generated
// only when a build needs them), then it is opened. Without one, `outcome` is marked skipped with the reason
// and the source is null. `outcome.points` and `description` come from the octree.
struct DatasetSource {
  std::unique_ptr<lod::NodeSource> source;
  DatasetOctree octree;
};
// Notes where the octree came from, or why the data set is skipped.
DatasetSource openDatasetOctree(const Dataset& dataset, const OctreeProvider& octrees, bool progress,
                                DatasetOutcome& outcome, const Note& note);

// Runs a data set's measurements: a damaged octree found while streaming (InputError) or a step the device
// cannot take (UnsupportedError) stops this data set with a note, not the run.
void measureDataset(const Dataset& dataset, const Note& note, const std::function<void()>& measure);

// Measures config's LOD methods on the octree of `dataset` (whose points are `cloud`) from each of `views`,
// each result filed under `order` (an octree is built from the points whatever their order) and handed to
// `record` as it is done; the octree goes to run.octrees. Without an octree (no provider, or it failed) the
// results say why. A DeviceFault ends the run as in runBench.
void measureOctreeMethods(gpu::Context& context, Renderer& renderer, const BenchConfig& config,
                          const Dataset& dataset, const PointCloud& cloud, Order order,
                          const std::vector<View>& views, BenchRun& run,
                          const std::function<void(const Result&)>& record);

} // namespace pointrast::bench

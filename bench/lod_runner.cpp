#include "bench/lod_runner.h"

#include <filesystem>
#include <memory>
#include <optional>

#include "bench/suites.h"
#include "io/format_table.h"
#include "render/lod/lod_scene.h"

namespace pointrast::bench {

namespace {

std::vector<Method> octreeMethods(const std::vector<Method>& methods) {
  std::vector<Method> out;
  for (Method m : methods)
    if (methodInfo(m).layout == SceneLayout::Octree) out.push_back(m);
  return out;
}

// The data set's octree opened as a LodScene with the default node cache, or why not.
struct OpenOctree {
  std::unique_ptr<lod::NodeSource> source;
  std::unique_ptr<lod::LodScene> scene;
  std::string failure;
};

OpenOctree openOctree(gpu::Context& context, const BenchConfig& config, const Dataset& dataset,
                      const PointCloud& cloud, BenchRun& run) {
  OpenOctree o;
  try {
    if (!config.octrees) throw InputError("no octree: this run has no octree builder or cache");
    DatasetOctree octree = config.octrees(octreeKey(dataset), [&]() -> const PointCloud& { return cloud; });
    o.source = io::openNodeSource(octree.path);
    o.scene = std::make_unique<lod::LodScene>(context, *o.source);
    run.octrees.emplace_back(dataset.name, std::move(octree));
  } catch (const InputError& e) {
    o.failure = e.what();
  } catch (const UnsupportedError& e) {
    o.failure = e.what();
  }
  return o;
}

} // namespace

std::string octreeKey(const Dataset& dataset) {
  if (dataset.file) return dataset.name + "-" + std::filesystem::path(dataset.source).stem().string();
  return dataset.name + "-" + std::to_string(dataset.points) + "-seed" + std::to_string(dataset.seed);
}

void measureOctreeMethods(gpu::Context& context, Renderer& renderer, const BenchConfig& config,
                          const Dataset& dataset, const PointCloud& cloud, Order order,
                          const std::vector<View>& views, BenchRun& run,
                          const std::function<void(const Result&)>& record) {
  const std::vector<Method> methods = octreeMethods(config.methods);
  if (methods.empty() || views.empty()) return;
  OpenOctree octree = openOctree(context, config, dataset, cloud, run);
  const double aspect = double(config.width) / double(config.height);
  // Clocks up again after the build, with the first method the device runs.
  const Camera first = viewCamera(views.front(), cloud.bounds, aspect, config.fovY);
  settleWithFirst(
      context, methods, [&](Method m) { return octree.scene && Renderer::supports(context, m); },
      [&](const RenderSettings& s) { return renderer.render(*octree.scene, first, s); });
  for (View view : views) {
    const Camera camera = viewCamera(view, cloud.bounds, aspect, config.fovY);
    for (Method method : methods) {
      Result r;
      r.dataset = dataset.name;
      r.order = order;
      r.view = view;
      r.method = method;
      r.points = cloud.size();
      r.bytesPerPoint = methodInfo(method).bytesPerPoint;
      r.camera = describeCamera(camera);
      std::string why;
      if (!octree.scene) {
        r.status = "unsupported";
        r.reason = octree.failure;
      } else if (!Renderer::supports(context, method, &why)) {
        r.status = "unsupported";
        r.reason = why;
      } else {
        measureGuarded(
            r,
            [&] {
              r.stats = timeFrames(method, run, [&](const RenderSettings& s) {
                return renderer.render(*octree.scene, camera, s);
              });
            },
            record);
      }
      completeRates(r, run.copy);
      record(r);
    }
  }
}

DatasetSource openDatasetOctree(const Dataset& dataset, const OctreeProvider& octrees, bool progress,
                                DatasetOutcome& outcome, const Note& note) {
  outcome.dataset = dataset;
  std::optional<PointCloud> cloud; // the build's input, released when this returns
  auto points = [&]() -> const PointCloud& {
    if (!cloud) cloud = loadDataset(dataset, progress);
    return *cloud;
  };
  DatasetSource d;
  try {
    if (!octrees) throw InputError("no octree: this run has no octree builder or cache");
    d.octree = octrees(octreeKey(dataset), points);
    d.source = io::openNodeSource(d.octree.path);
  } catch (const InputError& e) {
    outcome.skipped = true;
    outcome.reason = e.what();
  } catch (const UnsupportedError& e) {
    outcome.skipped = true;
    outcome.reason = e.what();
  }
  if (!d.source) {
    note(dataset.label + ": skipped, " + outcome.reason);
    return d;
  }
  outcome.points = d.source->metadata().pointCount;
  outcome.description = d.source->metadata().source + " (" + d.source->metadata().format + ")";
  note(dataset.label + ": octree " + d.octree.path.string() +
       (d.octree.reused ? " (from the cache)" : " built in " + printf1("%.1f s", d.octree.buildSeconds)));
  return d;
}

void measureDataset(const Dataset& dataset, const Note& note, const std::function<void()>& measure) {
  try {
    measure();
  } catch (const InputError& e) {
    note(dataset.label + ": stopped, " + e.what());
  } catch (const UnsupportedError& e) {
    note(dataset.label + ": stopped, " + e.what());
  }
}

} // namespace pointrast::bench

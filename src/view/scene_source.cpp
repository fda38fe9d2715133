#include "view/scene_source.h"

#include <cassert>

#include "base/error.h"
#include "gpu/context.h"
#include "render/lod/lod_scene.h"
#include "view/scene_view.h"

namespace pointrast::view {

namespace {
constexpr uint64_t kInteractiveUploadBytes = uint64_t(32) << 20;
// Node readers keep every core busy while the camera meets new ground; below the frame's threads (render,
// JPEG, the sockets) they take only the time those leave.
constexpr int kInteractiveReaderNiceness = 10;
} // namespace

SceneInput::SceneInput() = default;
SceneInput::SceneInput(SceneInput&&) noexcept = default;
SceneInput& SceneInput::operator=(SceneInput&&) noexcept = default;
SceneInput::~SceneInput() = default;

SceneInput SceneInput::fromCloud(PointCloud cloud) {
  SceneInput input;
  input.name = cloud.source;
  input.bounds = cloud.bounds;
  input.points = cloud.size();
  input.framing = framingSample(cloud);
  input.cloud = std::make_unique<PointCloud>(std::move(cloud));
  return input;
}

SceneInput SceneInput::fromOctree(std::unique_ptr<lod::NodeSource> source) {
  const lod::OctreeMetadata& octree = source->metadata();
  SceneInput input;
  input.name = octree.source;
  input.bounds = octree.bounds.empty() ? octree.cube : octree.bounds;
  input.points = octree.pointCount;
  if (input.bounds.empty()) throw InputError(octree.source + ": the octree states no extent");
  input.framing = framingSample(*source);
  input.octree = std::move(source);
  return input;
}

std::vector<Method> methodsFor(const SceneSource& source, const gpu::Context& context) {
  std::vector<Method> methods;
  for (Method m : allMethods())
    if (source.draws(m) && !source.refuses(m) && Renderer::supports(const_cast<gpu::Context&>(context), m))
      methods.push_back(m);
  return methods;
}

std::string notDrawn(const SceneSource& source, Method method) {
  const std::string methods = source.streamed() ? methodNamesReading(SceneLayout::Octree)
                                                : methodNamesReading(SceneLayout::Float) + ", " +
                                                      methodNamesReading(SceneLayout::Batched);
  return std::string("--method ") + methodName(method) + " does not draw " + source.name() +
         (source.streamed() ? ", an octree" : ", a cloud drawn whole") + ": its methods are " + methods;
}

Method defaultMethod(const SceneSource& source, const gpu::Context& context) {
  auto runs = [&](Method m) { return Renderer::supports(const_cast<gpu::Context&>(context), m); };
  if (source.streamed()) return pointMethod("lod");
  if (context.info().type == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU && runs(pointMethod("batch-prefetch")))
    return pointMethod("batch-prefetch");
  return pointMethod("atomicmin");
}

bool GpuOctree::Options::operator==(const Options& other) const {
  const bool sameRange =
      colorRange.has_value() == other.colorRange.has_value() &&
      (!colorRange || (colorRange->lo == other.colorRange->lo && colorRange->hi == other.colorRange->hi));
  return colorSource == other.colorSource && sameRange && gpuBytes == other.gpuBytes;
}

GpuOctree::Options GpuOctree::optionsOf(const ViewSettings& settings) {
  return {settings.colorSource, settings.colorRange, settings.gpuMemory};
}

GpuOctree::GpuOctree(gpu::Context& context, lod::NodeSource& source, const std::string& name,
                     const Bounds& bounds, uint64_t points, const ViewSettings& settings, DrawShare share)
    : context_(context), source_(source), name_(name), bounds_(bounds), points_(points), share_(share) {
  make(optionsOf(settings));
}

GpuOctree::~GpuOctree() = default;

void GpuOctree::make(const Options& options) {
  lod::LodOptions o;
  o.colorSource = options.colorSource;
  o.colorRange = options.colorRange;
  o.gpuBytes = options.gpuBytes;
  // Node bytes one interactive frame copies to the GPU: 32 MiB take under 2 ms at PCIe speed, so a frame
  // that streams new nodes stays near a frame time while the camera moves (the offline default, 256 MiB,
  // made the frames that met new ground several times slower than the rest); a jump that needs more
  // refines over a few more frames.
  o.uploadBytesPerFrame = kInteractiveUploadBytes;
  o.readerNiceness = kInteractiveReaderNiceness;
  o.shareIndex = share_.index;
  o.shares = share_.count;
  scene_.reset(); // its node cache goes before the new one is allocated
  scene_ = std::make_unique<lod::LodScene>(context_, source_, o);
  options_ = options;
  converged_ = false;
  failed_ = false;
}

uint64_t GpuOctree::bytes() const {
  return scene_ ? scene_->stats().residentBytes : 0;
}

FrameStats GpuOctree::draw(Renderer& renderer, const Camera& camera, const RenderSettings& rs,
                           const ViewSettings& settings, std::string& status) {
  const Options wanted = optionsOf(settings);
  if (!(wanted == options_)) {
    const Options previous = options_;
    // Colors the octree cannot show, or a budget that holds no page: back to what drew before, said once
    // per change rather than retried every frame.
    auto refuse = [&](const char* why) {
      error_ = why;
      make(previous);
      options_ = wanted;
    };
    try {
      make(wanted);
      error_.clear();
    } catch (const InputError& e) {
      refuse(e.what());
    } catch (const UnsupportedError& e) {
      refuse(e.what());
    }
  }
  if (!error_.empty()) status = error_;
  failed_ = false;
  try {
    FrameStats stats = renderer.renderFrame(*scene_, camera, rs);
    converged_ = stats.lod && stats.lod->converged;
    return stats;
  } catch (const InputError& e) {
    // A damaged node: say so and keep the viewer running; input draws again.
    status = e.what();
    failed_ = true;
    converged_ = false;
    return {};
  }
}

std::unique_ptr<SceneSource> makeSceneSource(gpu::Context& context, SceneInput& input,
                                             const ViewSettings& settings, bool progress, DrawShare share) {
  if (input.octree)
    return std::make_unique<GpuOctree>(context, *input.octree, input.name, input.bounds, input.points,
                                       settings, share);
  assert(input.cloud && "an input holds a cloud or an octree");
  return std::make_unique<GpuCloud>(context, *input.cloud, progress);
}

} // namespace pointrast::view

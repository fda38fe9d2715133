#include "render/renderer.h"

#include <algorithm>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"
#include "gpu/timer.h"

namespace pointrast {

namespace {

constexpr MethodInfo kMethods[] = {
    {Method::AtomicMin, "atomicmin", "one 64-bit atomicMin of depth<<32|color per point (2019)"},
};

// 16384 x 16384 pixels: 2 GiB of framebuffer words, the most a single allocation is guaranteed to hold
// on common devices.
constexpr uint32_t kMaxSide = 16384;

} // namespace

std::span<const MethodInfo> methodTable() { return kMethods; }

Method parseMethod(std::string_view name) {
  std::string known;
  for (const MethodInfo& m : kMethods) {
    if (name == m.name) return m.method;
    known += known.empty() ? "" : ", ";
    known += m.name;
  }
  throw InputError("unknown method '" + std::string(name) + "'; choose one of: " + known);
}

const char* methodName(Method method) {
  for (const MethodInfo& m : kMethods)
    if (m.method == method) return m.name;
  return "?";
}

Renderer::Renderer(gpu::Context& context, uint32_t width, uint32_t height)
    : context_(context), width_(width), height_(height) {
  if (width == 0 || height == 0 || width > kMaxSide || height > kMaxSide)
    throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is out of range (1.." + std::to_string(kMaxSide) + " per side)");
  uint64_t pixels = uint64_t(width) * height;
  framebuffer_ = gpu::Buffer(context, pixels * 8, gpu::kBufferUsage, gpu::MemoryKind::Device, "framebuffer");
  image_ = gpu::Buffer(context, pixels * 4, gpu::kBufferUsage, gpu::MemoryKind::Device, "image");
  atomicMin_ = gpu::ComputeProgram(context, "raster_atomicmin.comp");
  resolve_ = gpu::ComputeProgram(context, "resolve.comp");
}

Renderer::~Renderer() = default;

void Renderer::recordFrame(VkCommandBuffer cmd, std::span<const GpuScene* const> scenes, const Camera& camera,
                           const RenderSettings& settings) {
  uint64_t pixels = uint64_t(width_) * height_;
  // Clear: all ones is kEmptyPixel.
  gpu::vkCmdFillBuffer(cmd, framebuffer_.handle(), 0, pixels * 8, 0xFFFFFFFFu);
  gpu::fullBarrier(cmd);
  double aspect = double(width_) / double(height_);
  for (const GpuScene* scene : scenes) {
    shared::RasterPush push{};
    push.viewProj = glm::mat4(viewProjection(camera, scene->origin(), aspect));
    push.framebuffer = framebuffer_.address();
    push.width = width_;
    push.height = height_;
    push.nearW = float(camera.nearW > 0 ? camera.nearW : defaultNear(scene->bounds()));
    for (const ScenePart& part : scene->parts()) {
      gpu::Grid grid = gpu::gridFor(part.count, atomicMin_.groupSize());
      push.positions = part.positions.address();
      push.colors = part.colors.address();
      push.pointCount = uint32_t(part.count);
      push.groupsX = grid.x;
      switch (settings.method) {
      case Method::AtomicMin: atomicMin_.dispatch(cmd, grid.x, grid.y, push); break;
      }
    }
  }
  gpu::fullBarrier(cmd);
  shared::ResolvePush resolve{};
  resolve.framebuffer = framebuffer_.address();
  resolve.image = image_.address();
  resolve.width = width_;
  resolve.height = height_;
  resolve.background = settings.background;
  gpu::Grid grid = gpu::gridFor(pixels, resolve_.groupSize());
  resolve.groupsX = grid.x;
  resolve_.dispatch(cmd, grid.x, grid.y, resolve);
  gpu::fullBarrier(cmd);
}

FrameStats Renderer::render(std::span<const GpuScene* const> scenes, const Camera& camera,
                            const RenderSettings& settings) {
  validateCamera(camera);
  uint32_t frames = std::max(1u, settings.frames);
  gpu::TimestampPool timestamps(context_, frames);
  context_.submitAndWait([&](VkCommandBuffer cmd) {
    timestamps.reset(cmd);
    for (uint32_t w = 0; w < settings.warmup; ++w) recordFrame(cmd, scenes, camera, settings);
    for (uint32_t f = 0; f < frames; ++f) {
      timestamps.begin(cmd, f);
      recordFrame(cmd, scenes, camera, settings);
      timestamps.end(cmd, f);
    }
  });
  std::vector<double> ms = timestamps.milliseconds();
  FrameStats stats;
  stats.frames = frames;
  stats.medianMs = gpu::median(ms);
  stats.minMs = *std::min_element(ms.begin(), ms.end());
  stats.maxMs = *std::max_element(ms.begin(), ms.end());
  for (const GpuScene* scene : scenes) stats.points += scene->pointCount();
  return stats;
}

std::vector<uint32_t> Renderer::image() {
  std::vector<uint32_t> pixels(uint64_t(width_) * height_);
  gpu::readBuffer(context_, image_, 0, pixels.data(), pixels.size() * 4);
  return pixels;
}

std::vector<uint64_t> Renderer::framebufferWords() {
  std::vector<uint64_t> words(uint64_t(width_) * height_);
  gpu::readBuffer(context_, framebuffer_, 0, words.data(), words.size() * 8);
  return words;
}

} // namespace pointrast

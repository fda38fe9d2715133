#include "render/spheres/sphere_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "base/error.h"
#include "gpu/context.h"
#include "gpu/timer.h"
#include "render/spheres/sphere_method.h"

namespace pointrast {

namespace {

bool alwaysSupported(gpu::Context&, std::string*) {
  return true;
}

bool pointsSupported(gpu::Context& context, std::string* why) {
  const gpu::DeviceFeatures& f = context.features();
  if (!f.largePoints || context.properties().limits.pointSizeRange[1] <= 1.0f) {
    *why = "the device draws no points larger than one pixel (largePoints)";
    return false;
  }
  if (!f.vertexStores) {
    *why = "the vertex shader counts clamped point sizes, which needs vertexPipelineStoresAndAtomics";
    return false;
  }
  return true;
}

bool geometrySupported(gpu::Context& context, std::string* why) {
  if (context.features().geometryShader) return true;
  *why = "the device has no geometry shaders";
  return false;
}

constexpr SphereMethodInfo kSphereMethods[] = {
    {SphereMethod::Compute, "sphere-compute",
     "compute rasterization of ray-cast spheres into a 64-bit depth|index visibility buffer; large spheres "
     "split into 256-pixel chunks across workgroups; then a shading resolve",
     alwaysSupported},
    {SphereMethod::Points, "sphere-points",
     "hardware point list, gl_PointSize from the projected bounds (clamped to the largest point), ray-cast "
     "in the fragment shader (2023 study)",
     pointsSupported},
    {SphereMethod::Triangles, "sphere-triangles",
     "hardware triangle list, 6 vertices per sphere over its projected bounds, ray-cast in the fragment "
     "shader",
     alwaysSupported},
    {SphereMethod::Strip, "sphere-strip",
     "hardware 4-vertex triangle strips, one instance per sphere, ray-cast in the fragment shader",
     alwaysSupported},
    {SphereMethod::Geometry, "sphere-geom",
     "hardware points expanded into strips by a geometry shader, ray-cast in the fragment shader",
     geometrySupported},
};

// As the point renderer: 16384 x 16384 pixels, 2 GiB of visibility words.
constexpr uint32_t kMaxSide = 16384;

// The frame constants of a camera (DESIGN.md's contract): view = lookAt relative to the particles' origin,
// computed in double and rounded once; the ray of pixel position (x, y) is (x sx + ox, y sy + oy, -1),
// the inverse of px = (c.x / c.w + 1) / 2 W, py = (1 - c.y / c.w) / 2 H with the projection of
// viewProjection() (c.x / c.w = x_view / (depth tanX), c.y / c.w = y_view / (depth tanY)).
shared::SphereFrame frameConstants(const GpuParticles& particles, const Camera& camera, uint32_t width,
                                   uint32_t height) {
  shared::SphereFrame f{};
  glm::dvec3 origin = particles.origin();
  f.view = glm::mat4(glm::lookAtRH(camera.eye - origin, camera.target - origin, camera.up));
  double tanY = std::tan(glm::radians(camera.fovY) / 2);
  double tanX = tanY * double(width) / double(height);
  f.pixelToRay = glm::vec4(float(2 * tanX / width), float(-tanX), float(-2 * tanY / height), float(tanY));
  f.width = width;
  f.height = height;
  f.nearW = float(camera.nearW > 0 ? camera.nearW : defaultNear(particles.bounds()));
  f.globalRadius = particles.globalRadius();
  f.globalColor = particles.globalColor();
  f.partCapacity = uint32_t(std::min<uint64_t>(particles.partCapacity(), 0xFFFFFFFFu));
  f.parts = particles.partTable().address();
  return f;
}

} // namespace

std::span<const SphereMethodInfo> sphereMethodTable() {
  return kSphereMethods;
}

const SphereMethodInfo& sphereMethodInfo(SphereMethod method) {
  for (const SphereMethodInfo& m : kSphereMethods)
    if (m.method == method) return m;
  return kSphereMethods[0];
}

bool isSphereMethodName(std::string_view name) {
  return std::any_of(std::begin(kSphereMethods), std::end(kSphereMethods),
                     [&](const SphereMethodInfo& m) { return name == m.name; });
}

SphereMethod parseSphereMethod(std::string_view name) {
  std::string known;
  for (const SphereMethodInfo& m : kSphereMethods) {
    if (name == m.name) return m.method;
    known += (known.empty() ? "" : ", ") + std::string(m.name);
  }
  throw InputError("unknown sphere method '" + std::string(name) + "'; choose one of: " + known);
}

const char* sphereMethodName(SphereMethod method) {
  return sphereMethodInfo(method).name;
}

bool SphereRenderer::supports(gpu::Context& context, SphereMethod method, std::string* why) {
  std::string reason;
  if (sphereMethodInfo(method).supported(context, &reason)) return true;
  if (why)
    *why = std::string(sphereMethodName(method)) + " is not available on '" + context.info().name +
           "': " + reason;
  return false;
}

SphereRenderer::SphereRenderer(gpu::Context& context, uint32_t width, uint32_t height)
    : context_(context), targets_(std::make_unique<SphereTargets>()) {
  if (width == 0 || height == 0 || width > kMaxSide || height > kMaxSide)
    throw InputError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is out of range (1.." + std::to_string(kMaxSide) + " per side)");
  SphereTargets& t = *targets_;
  t.width = width;
  t.height = height;
  t.image = gpu::Buffer(context, t.pixels() * 4, gpu::kBufferUsage, gpu::MemoryKind::Device, "sphere image");
  t.frame = gpu::Buffer(context, sizeof(shared::SphereFrame), gpu::kBufferUsage, gpu::MemoryKind::Device,
                        "sphere frame constants");
  t.frameStaging = gpu::Buffer(context, sizeof(shared::SphereFrame), gpu::kBufferUsage,
                               gpu::MemoryKind::Upload, "sphere frame constants staging");
}

SphereRenderer::~SphereRenderer() = default;

uint32_t SphereRenderer::width() const {
  return targets_->width;
}
uint32_t SphereRenderer::height() const {
  return targets_->height;
}

SphereMethodImpl& SphereRenderer::method(SphereMethod method) {
  std::string why;
  if (!supports(context_, method, &why)) throw UnsupportedError(why);
  for (auto& [m, impl] : methods_)
    if (m == method) return *impl;
  std::unique_ptr<SphereMethodImpl> created;
  switch (method) {
  case SphereMethod::Compute:
    created = createSphereComputeMethod(context_, targets_->width, targets_->height);
    break;
  case SphereMethod::Points:
  case SphereMethod::Triangles:
  case SphereMethod::Strip:
  case SphereMethod::Geometry:
    created = createSphereHardwareMethod(context_, targets_->width, targets_->height, method);
    break;
  }
  methods_.emplace_back(method, std::move(created));
  return *methods_.back().second;
}

SphereStats SphereRenderer::render(const GpuParticles& particles, const Camera& camera,
                                   const SphereSettings& settings) {
  validateCamera(camera);
  SphereMethodImpl& m = method(settings.method);
  SphereTargets& t = *targets_;
  shared::SphereFrame frame = frameConstants(particles, camera, t.width, t.height);
  frame.image = t.image.address();
  frame.background = settings.background;
  m.prepare(settings, frame);
  std::memcpy(t.frameStaging.mapped(), &frame, sizeof frame);

  uint32_t frames = std::max(1u, settings.frames);
  gpu::TimestampPool timestamps(context_, frames);
  context_.submitAndWait([&](VkCommandBuffer cmd) {
    timestamps.reset(cmd);
    VkBufferCopy region{0, 0, sizeof frame};
    gpu::vkCmdCopyBuffer(cmd, t.frameStaging.handle(), t.frame.handle(), 1, &region);
    gpu::fullBarrier(cmd);
    SphereDraw draw{cmd, particles, settings};
    for (uint32_t w = 0; w < settings.warmup; ++w)
      m.recordFrame(draw, t);
    for (uint32_t f = 0; f < frames; ++f) {
      timestamps.begin(cmd, f);
      m.recordFrame(draw, t);
      timestamps.end(cmd, f);
    }
  });
  last_ = &m;
  std::vector<double> ms = timestamps.milliseconds();
  SphereStats stats;
  stats.frames = frames;
  stats.medianMs = gpu::median(ms);
  stats.minMs = *std::min_element(ms.begin(), ms.end());
  stats.maxMs = *std::max_element(ms.begin(), ms.end());
  stats.particles = particles.count();
  m.addCounters(stats);
  return stats;
}

std::vector<uint32_t> SphereRenderer::image() {
  std::vector<uint32_t> pixels(targets_->pixels());
  gpu::readBuffer(context_, targets_->image, 0, pixels.data(), pixels.size() * 4);
  return pixels;
}

std::vector<float> SphereRenderer::depth() {
  if (!last_) throw InputError("no sphere frame has been rendered yet");
  return last_->depth();
}

std::vector<uint32_t> SphereRenderer::indices() {
  if (!last_) throw InputError("no sphere frame has been rendered yet");
  return last_->indices();
}

} // namespace pointrast

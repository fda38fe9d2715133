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

bool meshPointsSupported(gpu::Context& context, std::string* why) {
  return sphereMeshSupported(context, /* points= */ true, why);
}

bool meshTrianglesSupported(gpu::Context& context, std::string* why) {
  return sphereMeshSupported(context, /* points= */ false, why);
}

bool rayTracingSupported(gpu::Context& context, std::string* why) {
  return sphereRtSupported(context, why);
}

// Billboard options of the rasterization pipelines: both billboards everywhere; conservative rasterization
// where the device has VK_EXT_conservative_rasterization, and for points only where it covers points.
bool billboardOptions(gpu::Context& context, const SphereSettings& settings, std::string* why) {
  if (!settings.conservative) return true;
  if (context.features().conservativeRasterization) return true;
  *why = "the device has no conservative rasterization (VK_EXT_conservative_rasterization)";
  return false;
}

bool pointBillboardOptions(gpu::Context& context, const SphereSettings& settings, std::string* why) {
  if (!billboardOptions(context, settings, why)) return false;
  if (!settings.conservative || context.features().conservativePoints) return true;
  *why = "the device rasterizes no points conservatively (conservativePointAndLineRasterization)";
  return false;
}

constexpr SphereMethodInfo kSphereMethods[] = {
    {SphereMethod::Compute, "sphere-compute",
     "compute rasterization of ray-cast spheres into a 64-bit depth|index visibility buffer; batches of "
     "128 neighboring particles hidden behind what the last frame's visible batches drew are skipped; large "
     "spheres split into 16x16-pixel tiles across workgroups, tiles hidden behind nearer spheres skipped; "
     "then a shading resolve",
     alwaysSupported},
    {SphereMethod::Points, "sphere-points",
     "hardware point list, gl_PointSize from the projected bounds (clamped to the largest point), ray-cast "
     "in the fragment shader (2023 study)",
     pointsSupported, pointBillboardOptions},
    {SphereMethod::Triangles, "sphere-triangles",
     "hardware triangle list, 6 vertices per sphere over its projected bounds, ray-cast in the fragment "
     "shader",
     alwaysSupported, billboardOptions},
    {SphereMethod::Strip, "sphere-strip",
     "hardware 4-vertex triangle strips, one instance per sphere, ray-cast in the fragment shader",
     alwaysSupported, billboardOptions},
    {SphereMethod::Geometry, "sphere-geom",
     "hardware points expanded into strips by a geometry shader, ray-cast in the fragment shader",
     geometrySupported, billboardOptions},
    {SphereMethod::MeshPoints, "sphere-mesh-points",
     "VK_EXT_mesh_shader: a meshlet of 31 or 15 spheres per workgroup (--meshlet; --task-cull culls first), "
     "one point each, gl_PointSize from the projected bounds (clamped to the largest point), ray-cast in the "
     "fragment shader (2023 study)",
     meshPointsSupported, pointBillboardOptions},
    {SphereMethod::MeshTriangles, "sphere-mesh-tris",
     "VK_EXT_mesh_shader: a meshlet of 31 or 15 spheres per workgroup (--meshlet; --task-cull culls first), "
     "a quad of 2 triangles over each one's projected bounds, ray-cast in the fragment shader (2023 study)",
     meshTrianglesSupported, billboardOptions},
    {SphereMethod::RayTracing, "sphere-rt",
     "VK_KHR_ray_tracing_pipeline: an acceleration structure of one AABB per sphere (built before the "
     "frames, timed apart), a ray per pixel, the shared intersection in an intersection shader, then the "
     "shading resolve of sphere-compute",
     rayTracingSupported},
};

// As the point renderer: 16384 x 16384 pixels, 2 GiB of visibility words.
constexpr uint32_t kMaxSide = 16384;

// The frame constants of a camera (docs/design.md's contract): view = lookAt relative to the particles' origin,
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

bool sphereMethodTakesBillboards(SphereMethod method) {
  return sphereMethodInfo(method).rasterOptions != nullptr;
}

std::string billboardMethodNames() {
  std::string names;
  for (const SphereMethodInfo& m : kSphereMethods)
    if (m.rasterOptions) names += (names.empty() ? "" : ", ") + std::string(m.name);
  return names;
}

SphereBillboard parseSphereBillboard(std::string_view name) {
  if (name == "screen") return SphereBillboard::Screen;
  if (name == "camera") return SphereBillboard::Camera;
  throw InputError("unknown billboard '" + std::string(name) + "'; choose screen or camera");
}

const char* sphereBillboardName(SphereBillboard billboard) {
  return billboard == SphereBillboard::Camera ? "camera" : "screen";
}

bool SphereRenderer::supports(gpu::Context& context, const SphereSettings& settings, std::string* why) {
  const SphereMethodInfo& info = sphereMethodInfo(settings.method);
  if (!info.rasterOptions && (settings.billboard != SphereBillboard::Screen || settings.conservative))
    throw InputError(
        std::string("billboard shapes and conservative rasterization apply to the sphere methods "
                    "that rasterize billboards (") +
        billboardMethodNames() + "); " + info.name + " draws none");
  if (!supports(context, settings.method, why)) return false;
  std::string reason;
  if (!info.rasterOptions || info.rasterOptions(context, settings, &reason)) return true;
  if (why)
    *why = std::string(info.name) + (settings.conservative ? " with conservative rasterization" : "") +
           " is not available on '" + context.info().name + "': " + reason;
  return false;
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
  case SphereMethod::MeshPoints:
  case SphereMethod::MeshTriangles:
    created = createSphereMeshMethod(context_, targets_->width, targets_->height, method);
    break;
  case SphereMethod::RayTracing:
    created = createSphereRtMethod(context_, targets_->width, targets_->height);
    break;
  }
  methods_.emplace_back(method, std::move(created));
  return *methods_.back().second;
}

SphereStats SphereRenderer::render(const GpuParticles& particles, const Camera& camera,
                                   const SphereSettings& settings) {
  validateCamera(camera);
  bool mesh = settings.method == SphereMethod::MeshPoints || settings.method == SphereMethod::MeshTriangles;
  if (settings.meshlet != shared::kSphereMeshletLarge && settings.meshlet != shared::kSphereMeshletSmall)
    throw InputError("a meshlet holds " + std::to_string(shared::kSphereMeshletLarge) + " or " +
                     std::to_string(shared::kSphereMeshletSmall) + " spheres, not " +
                     std::to_string(settings.meshlet));
  if (!mesh && (settings.taskCull || settings.meshlet != shared::kSphereMeshletLarge))
    throw InputError(
        std::string("meshlet sizes and task-shader culling apply to sphere-mesh-points and sphere-mesh-tris, "
                    "not to ") +
        sphereMethodName(settings.method));
  std::string why;
  if (!supports(context_, settings, &why)) throw UnsupportedError(why);
  SphereMethodImpl& m = method(settings.method);
  SphereTargets& t = *targets_;
  shared::SphereFrame frame = frameConstants(particles, camera, t.width, t.height);
  frame.image = t.image.address();
  frame.background = settings.background;
  m.prepare(settings, frame);
  std::memcpy(t.frameStaging.mapped(), &frame, sizeof frame);
  double buildMs = m.build(particles, t); // sphere-rt's acceleration structures; timed apart from frames

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
  lastOrder_ = particles.order();
  std::vector<double> ms = timestamps.milliseconds();
  SphereStats stats;
  stats.frames = frames;
  stats.medianMs = gpu::median(ms);
  stats.minMs = *std::min_element(ms.begin(), ms.end());
  stats.maxMs = *std::max_element(ms.begin(), ms.end());
  stats.particles = particles.count();
  stats.buildMs = buildMs;
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
  std::vector<uint32_t> indices = last_->indices();
  if (lastOrder_) // GPU positions -> indices of the set
    for (uint32_t& i : indices)
      if (i != shared::kNoParticle) i = (*lastOrder_)[i];
  return indices;
}

} // namespace pointrast

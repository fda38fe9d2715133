// The interface every sphere method implements (internal to src/render/spheres). A method owns its
// programs and buffers beyond the shared targets and records one whole frame: clear, draw every part,
// resolve into the RGBA8 image. The SphereRenderer times frames and owns the targets.
#pragma once

#include <vector>

#include "gpu/buffer.h"
#include "gpu/shared_types.h"
#include "render/spheres/sphere_renderer.h"

namespace pointrast {

struct SphereTargets {
  uint32_t width = 0, height = 0;
  gpu::Buffer image;        // RGBA8 per pixel
  gpu::Buffer frame;        // SphereFrame, device-local: every thread of every pass reads it
  gpu::Buffer frameStaging; // SphereFrame, host-visible, copied into `frame` at the start of render()
  uint64_t pixels() const { return uint64_t(width) * height; }
};

struct SphereDraw {
  VkCommandBuffer cmd;
  const GpuParticles& particles;
  const SphereSettings& settings;
};

class SphereMethodImpl {
public:
  virtual ~SphereMethodImpl() = default;
  // Called before recording: fills the method's fields of the frame constants (framebuffer, chunks,
  // chunkCapacity) for this frame's settings.
  virtual void prepare(const SphereSettings& settings, shared::SphereFrame& frame) = 0;
  // Called after prepare(), with this frame's constants already in targets.frameStaging (host-visible),
  // before the frames are recorded: builds what the method derives from the particles in its own
  // submission (sphere-rt: the acceleration structures) and returns its GPU time in milliseconds from
  // timestamp queries, 0 when there is nothing to build.
  virtual double build(const GpuParticles& particles, SphereTargets& targets) {
    (void)particles;
    (void)targets;
    return 0;
  }
  virtual void recordFrame(const SphereDraw& draw, SphereTargets& targets) = 0;
  // After the frames completed: per-pixel view depth (+infinity where empty) and particle index
  // (kNoParticle where empty) of the last frame.
  virtual std::vector<float> depth() = 0;
  virtual std::vector<uint32_t> indices() = 0;
  // Method-specific counters of the last frame (sphere-compute: large chunks, spilled spheres;
  // sphere-points: clamped spheres).
  virtual void addCounters(SphereStats& stats) { (void)stats; }
};

std::unique_ptr<SphereMethodImpl> createSphereComputeMethod(gpu::Context& context, uint32_t width,
                                                            uint32_t height);
// sphere-mesh-points, sphere-mesh-tris (sphere_mesh.cpp): whether the device has mesh shaders with the
// limits both meshlet sizes need (why: one sentence when not).
bool sphereMeshSupported(gpu::Context& context, bool points, std::string* why);
std::unique_ptr<SphereMethodImpl> createSphereMeshMethod(gpu::Context& context, uint32_t width,
                                                         uint32_t height, SphereMethod method);
// sphere-rt (sphere_rt.cpp).
bool sphereRtSupported(gpu::Context& context, std::string* why);
std::unique_ptr<SphereMethodImpl> createSphereRtMethod(gpu::Context& context, uint32_t width,
                                                       uint32_t height);
// sphere-points, sphere-triangles, sphere-strip, sphere-geom.
std::unique_ptr<SphereMethodImpl> createSphereHardwareMethod(gpu::Context& context, uint32_t width,
                                                             uint32_t height, SphereMethod method);

} // namespace pointrast

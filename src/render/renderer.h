// Draws GPU scenes into a 64-bit framebuffer with a compute method and resolves it to an RGBA8 image.
// Every method writes the same framebuffer words for the same input and camera (DESIGN.md,
// "Equivalence"); they differ only in how they get there, which is what the benchmarks compare.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gpu/buffer.h"
#include "gpu/program.h"
#include "render/camera.h"
#include "render/scene.h"

namespace pointrast {

namespace gpu {
class Context;
}

enum class Method {
  AtomicMin, // 2019: one 64-bit atomicMin of (depth << 32 | color) per point
};

struct MethodInfo {
  Method method;
  const char* name;
  const char* description;
};
std::span<const MethodInfo> methodTable();
// Throws InputError listing the known names.
Method parseMethod(std::string_view name);
const char* methodName(Method method);

struct RenderSettings {
  Method method = Method::AtomicMin;
  uint32_t background = 0xFF000000u; // RGBA8, opaque black
  uint32_t frames = 1;               // timed frames; the median is reported
  uint32_t warmup = 1;               // untimed frames first (pipeline caches, clocks)
};

struct FrameStats {
  double medianMs = 0, minMs = 0, maxMs = 0; // GPU time of clear + draw + resolve, timestamp queries
  uint32_t frames = 0;
  uint64_t points = 0;                       // points submitted per frame
};

class Renderer {
public:
  // Throws InputError for a zero or oversized image.
  Renderer(gpu::Context& context, uint32_t width, uint32_t height);
  ~Renderer();

  // Draws every scene into one framebuffer per frame (all scenes share the camera), resolves, and keeps
  // the last frame's image on the GPU for image().
  FrameStats render(std::span<const GpuScene* const> scenes, const Camera& camera, const RenderSettings& settings);
  FrameStats render(const GpuScene& scene, const Camera& camera, const RenderSettings& settings) {
    const GpuScene* one[] = {&scene};
    return render(one, camera, settings);
  }

  // RGBA8 pixels of the last frame, row 0 at the top.
  std::vector<uint32_t> image();
  // The raw 64-bit framebuffer words of the last frame (before resolve), for equivalence tests.
  std::vector<uint64_t> framebufferWords();

  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }

private:
  void recordFrame(VkCommandBuffer cmd, std::span<const GpuScene* const> scenes, const Camera& camera,
                   const RenderSettings& settings);
  gpu::Context& context_;
  uint32_t width_, height_;
  gpu::Buffer framebuffer_; // uint64_t per pixel
  gpu::Buffer image_;       // uint per pixel
  gpu::ComputeProgram atomicMin_;
  gpu::ComputeProgram resolve_;
};

} // namespace pointrast

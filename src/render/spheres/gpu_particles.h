// A particle set (spheres) on the GPU in one of the layouts of Gralka et al., "Efficient Sphere Rendering
// Revisited" (2023), section 4: soa8, vec4x2, aos, xyz (byte layouts in shaders/shared.h). Like GpuScene it
// is split into parts that each fit one buffer, so any count works whatever the device's largest buffer;
// a table of SpherePartRef lets passes that see only a particle index (resolve, large spheres) find it.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cloud/particles.h"
#include "gpu/buffer.h"
#include "render/spheres/spheres.h"

namespace pointrast {

namespace gpu {
class Context;
}

enum class ParticleLayout {
  Soa8,   // 8 float streams x, y, z, r, R, G, B, A
  Vec4x2, // vec4 position + radius, vec4 color
  Aos,    // interleaved vec3 position + RGBA8 color, global radius
  Xyz,    // positions only, global radius and color
};

struct ParticleLayoutInfo {
  ParticleLayout layout;
  const char* name;
  const char* description;
  uint32_t shaderId;         // kSphereLayout* of shared.h
  uint32_t bytesPerParticle; // GPU bytes per particle (what a frame must read)
  bool perParticleRadius;    // holds a radius per particle
  bool perParticleColor;     // holds a color per particle
};
std::span<const ParticleLayoutInfo> particleLayoutTable();
const ParticleLayoutInfo& particleLayoutInfo(ParticleLayout layout);
// Throws InputError listing the known names.
ParticleLayout parseParticleLayout(std::string_view name);
const char* particleLayoutName(ParticleLayout layout);

// Whether a layout holds the set exactly (aos drops per-particle radii, xyz also per-particle colors);
// why: the reason in one sentence when it does not.
bool layoutHolds(ParticleLayout layout, const ParticleSet& set, std::string* why = nullptr);
// The most compact layout that holds the set exactly: xyz, else aos, else vec4x2.
ParticleLayout compactLayout(const ParticleSet& set);

// Whether `count` particles fit the device's memory in `layout` (nullopt: the most compact layout, the
// least any set of that count needs); when not, *why says so in one sentence. GpuParticles refuses what
// this refuses; a caller that knows the count early (a file's header) asks before reading anything.
bool particlesFit(const gpu::Context& context, std::optional<ParticleLayout> layout, uint64_t count,
                  std::string* why = nullptr);

struct ParticlePart {
  gpu::Buffer data;   // the part's particles in the layout (one buffer, streams at fixed offsets)
  uint64_t first = 0; // index of the part's first particle in the set
  uint64_t count = 0;
};

struct ParticleUploadOptions {
  std::optional<ParticleLayout> layout; // nullopt: compactLayout(set)
  uint64_t maxPartParticles = 0;        // 0: as many as fit one buffer, <= 64 M
  // Store the particles in spatial order (spatialOrder, cloud/order.h), so that consecutive particles lie close
  // together: sphere-compute's occlusion culling tests batches of consecutive particles by their bounds.
  // Indices reported by the renderers stay those of the set.
  bool spatialOrder = true;
  bool progress = true;
};

class GpuParticles {
public:
  // Uploads through a staging buffer. Throws InputError if the layout cannot hold the set, and
  // UnsupportedError if the set has 2^32 particles or more (a framebuffer word holds a 32-bit index) or
  // does not fit in GPU memory.
  GpuParticles(gpu::Context& context, const ParticleSet& set, const ParticleUploadOptions& options = {});

  uint64_t count() const { return count_; }
  ParticleLayout layout() const { return layout_; }
  const glm::dvec3& origin() const { return origin_; }
  // Of the spheres, radii included (what a camera must see and the default near plane derives from).
  const Bounds& bounds() const { return bounds_; }
  float globalRadius() const { return globalRadius_; }
  uint32_t globalColor() const { return globalColor_; }
  const std::vector<ParticlePart>& parts() const { return parts_; }
  // Particles per part; every part but the last holds exactly this many.
  uint64_t partCapacity() const { return partCapacity_; }
  // SpherePartRef per part, device-local.
  const gpu::Buffer& partTable() const { return partTable_; }
  // The set index of the particle at each GPU position (what the visibility buffers hold); null: the
  // set's own order.
  const std::shared_ptr<const std::vector<uint32_t>>& order() const { return order_; }
  // Unique per upload in this process: methods that derive data from the particles (sphere-compute's batch
  // bounds) rebuild it when the id changes.
  uint64_t id() const { return id_; }
  // GPU bytes of particle data (what a method that reads every particle once must read per frame).
  uint64_t bytes() const { return count_ * particleLayoutInfo(layout_).bytesPerParticle; }

private:
  std::vector<ParticlePart> parts_;
  gpu::Buffer partTable_;
  uint64_t count_ = 0;
  uint64_t partCapacity_ = 0;
  ParticleLayout layout_ = ParticleLayout::Vec4x2;
  glm::dvec3 origin_{0};
  Bounds bounds_;
  float globalRadius_ = 1.0f;
  uint32_t globalColor_ = 0;
  uint64_t id_ = 0;
  std::shared_ptr<const std::vector<uint32_t>> order_;
};

} // namespace pointrast

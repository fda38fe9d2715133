#include "render/spheres/gpu_particles.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstring>

#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "cloud/order.h"
#include "gpu/context.h"
#include "gpu/shared_types.h"

namespace pointrast {

namespace {

constexpr ParticleLayoutInfo kLayouts[] = {
    {ParticleLayout::Soa8, "soa8", "8 float streams x, y, z, r, R, G, B, A", shared::kSphereLayoutSoa8, 32,
     true, true},
    {ParticleLayout::Vec4x2, "vec4x2", "vec4 position + radius, vec4 color", shared::kSphereLayoutVec4x2, 32,
     true, true},
    {ParticleLayout::Aos, "aos", "interleaved vec3 position + RGBA8 color, one global radius",
     shared::kSphereLayoutAos, 16, false, true},
    {ParticleLayout::Xyz, "xyz", "positions only, one global radius and color", shared::kSphereLayoutXyz, 12,
     false, false},
};

constexpr uint64_t kStagingBytes = 64ull << 20; // per copy
constexpr uint64_t kMaxPartParticles = 64ull << 20;
constexpr uint64_t kMaxParticles = 0xFFFFFFFFull; // indices 0 .. 2^32 - 2 in the low word; see SphereFrame

// The streams of a layout, in the order they follow each other in a part's buffer: stream s of a part of
// n particles starts at byte n * (sum of the element sizes of the streams before it).
std::vector<uint32_t> streamElementBytes(ParticleLayout layout) {
  switch (layout) {
  case ParticleLayout::Soa8:
    return std::vector<uint32_t>(8, 4);
  case ParticleLayout::Vec4x2:
    return {16, 16};
  case ParticleLayout::Aos:
    return {16};
  case ParticleLayout::Xyz:
    return {12};
  }
  return {};
}

float channel(uint32_t rgba, int c) {
  return float((rgba >> (8 * c)) & 0xFFu) / 255.0f;
}

// Writes the particles at upload positions [first + begin, first + end) into the stream regions (region s
// holds stream s of the chunk starting at upload position `first`, tightly packed), reading upload
// position k from particle order[k] of the set (k itself without an order).
void fillStreams(ParticleLayout layout, const ParticleSet& set, const uint32_t* order, uint64_t first,
                 uint64_t begin, uint64_t end, const std::vector<char*>& regions) {
  auto source = [&](uint64_t i) -> uint64_t { return order ? order[first + i] : first + i; };
  const float* xyz = set.xyz.data();
  switch (layout) {
  case ParticleLayout::Soa8: {
    float* s[8];
    for (int k = 0; k < 8; ++k)
      s[k] = reinterpret_cast<float*>(regions[k]);
    for (uint64_t i = begin; i < end; ++i) {
      uint64_t j = source(i);
      uint32_t color = set.colorOf(j);
      s[0][i] = xyz[3 * j];
      s[1][i] = xyz[3 * j + 1];
      s[2][i] = xyz[3 * j + 2];
      s[3][i] = set.radiusOf(j);
      for (int c = 0; c < 4; ++c)
        s[4 + c][i] = channel(color, c);
    }
    break;
  }
  case ParticleLayout::Vec4x2: {
    auto* positions = reinterpret_cast<float*>(regions[0]);
    auto* colors = reinterpret_cast<float*>(regions[1]);
    for (uint64_t i = begin; i < end; ++i) {
      uint64_t j = source(i);
      uint32_t color = set.colorOf(j);
      std::memcpy(positions + 4 * i, xyz + 3 * j, 12);
      positions[4 * i + 3] = set.radiusOf(j);
      for (int c = 0; c < 4; ++c)
        colors[4 * i + c] = channel(color, c);
    }
    break;
  }
  case ParticleLayout::Aos: {
    char* out = regions[0];
    for (uint64_t i = begin; i < end; ++i) {
      uint64_t j = source(i);
      uint32_t color = set.colorOf(j);
      std::memcpy(out + 16 * i, xyz + 3 * j, 12);
      std::memcpy(out + 16 * i + 12, &color, 4);
    }
    break;
  }
  case ParticleLayout::Xyz:
    if (!order) {
      std::memcpy(regions[0] + 12 * begin, xyz + 3 * (first + begin), (end - begin) * 12);
    } else {
      for (uint64_t i = begin; i < end; ++i)
        std::memcpy(regions[0] + 12 * i, xyz + 3 * source(i), 12);
    }
    break;
  }
}

} // namespace

std::span<const ParticleLayoutInfo> particleLayoutTable() {
  return kLayouts;
}

const ParticleLayoutInfo& particleLayoutInfo(ParticleLayout layout) {
  for (const ParticleLayoutInfo& l : kLayouts)
    if (l.layout == layout) return l;
  return kLayouts[0];
}

ParticleLayout parseParticleLayout(std::string_view name) {
  std::string known;
  for (const ParticleLayoutInfo& l : kLayouts) {
    if (name == l.name) return l.layout;
    known += (known.empty() ? "" : ", ") + std::string(l.name);
  }
  throw InputError("unknown particle layout '" + std::string(name) + "'; choose one of: " + known);
}

const char* particleLayoutName(ParticleLayout layout) {
  return particleLayoutInfo(layout).name;
}

bool layoutHolds(ParticleLayout layout, const ParticleSet& set, std::string* why) {
  const ParticleLayoutInfo& info = particleLayoutInfo(layout);
  std::string reason;
  if (set.perParticleRadius() && !info.perParticleRadius)
    reason = "the particles have a radius each, but layout " + std::string(info.name) +
             " holds one global radius (use vec4x2 or soa8)";
  else if (set.perParticleColor() && !info.perParticleColor)
    reason = "the particles have a color each, but layout " + std::string(info.name) +
             " holds one global color (use aos, vec4x2 or soa8)";
  if (!reason.empty() && why) *why = reason;
  return reason.empty();
}

ParticleLayout compactLayout(const ParticleSet& set) {
  if (set.perParticleRadius()) return ParticleLayout::Vec4x2;
  if (set.perParticleColor()) return ParticleLayout::Aos;
  return ParticleLayout::Xyz;
}

bool particlesFit(const gpu::Context& context, std::optional<ParticleLayout> layout, uint64_t count,
                  std::string* why) {
  uint32_t perParticle = UINT32_MAX;
  const char* name = "";
  for (const ParticleLayoutInfo& info : particleLayoutTable())
    if ((!layout || info.layout == *layout) && info.bytesPerParticle < perParticle) {
      perParticle = info.bytesPerParticle;
      name = info.name;
    }
  // Computed in double: a hostile count times the bytes per particle must not wrap around to "fits".
  const double needed = double(count) * perParticle;
  if (needed <= double(context.deviceLocalBytes())) return true;
  if (why)
    *why = std::to_string(count) + " particles need " + std::to_string(uint64_t(needed / 1048576.0)) +
           " MiB of GPU memory (layout " + name + ", " + std::to_string(perParticle) +
           " B a particle) but device '" + context.info().name + "' has " +
           std::to_string(context.deviceLocalBytes() >> 20) + " MiB";
  return false;
}

GpuParticles::GpuParticles(gpu::Context& context, const ParticleSet& set,
                           const ParticleUploadOptions& options)
    : count_(set.size()), origin_(set.origin), bounds_(sphereBounds(set)), globalRadius_(set.globalRadius),
      globalColor_(set.globalColor) {
  static std::atomic<uint64_t> uploads{0};
  id_ = ++uploads;
  assert(set.xyz.size() % 3 == 0);
  assert(set.radius.empty() || set.radius.size() == count_);
  assert(set.colors.empty() || set.colors.size() == count_);
  layout_ = options.layout.value_or(compactLayout(set));
  std::string why;
  if (!layoutHolds(layout_, set, &why)) throw InputError(why);
  if (count_ > kMaxParticles)
    throw UnsupportedError("the sphere renderers index particles with 32 bits: at most " +
                           std::to_string(kMaxParticles) + " particles, this set has " +
                           std::to_string(count_));
  const ParticleLayoutInfo& info = particleLayoutInfo(layout_);
  if (!particlesFit(context, layout_, count_, &why))
    throw UnsupportedError("the particles do not fit: " + why);
  uint64_t limit = std::min(context.maxAllocationSize(), context.maxBufferSize());
  partCapacity_ = options.maxPartParticles;
  if (partCapacity_ == 0)
    partCapacity_ = std::min(kMaxPartParticles, (limit / info.bytesPerParticle) / shared::kSphereGroupSize *
                                                    shared::kSphereGroupSize);
  if (partCapacity_ == 0) throw UnsupportedError("device buffers are too small to hold a part of particles");

  for (uint64_t at = 0; at < count_; at += partCapacity_) {
    ParticlePart part;
    part.first = at;
    part.count = std::min(partCapacity_, count_ - at);
    part.data =
        gpu::Buffer(context, part.count * info.bytesPerParticle, gpu::kBufferUsage, gpu::MemoryKind::Device,
                    std::string("particles ") + info.name + " " + std::to_string(parts_.size()));
    parts_.push_back(std::move(part));
  }
  std::vector<shared::SpherePartRef> refs;
  for (const ParticlePart& part : parts_)
    refs.push_back({part.data.address(), uint32_t(part.count), 0});
  partTable_ = gpu::Buffer(context, std::max<size_t>(1, refs.size()) * sizeof(shared::SpherePartRef),
                           gpu::kBufferUsage, gpu::MemoryKind::Device, "particle part table");
  if (count_ == 0) return;

  gpu::Buffer staging(context, kStagingBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, gpu::MemoryKind::Upload,
                      "particle upload staging");
  std::memcpy(staging.mapped(), refs.data(), refs.size() * sizeof refs[0]);
  context.submitAndWait([&](VkCommandBuffer cmd) {
    VkBufferCopy region{0, 0, refs.size() * sizeof refs[0]};
    gpu::vkCmdCopyBuffer(cmd, staging.handle(), partTable_.handle(), 1, &region);
  });

  std::vector<uint32_t> elements = streamElementBytes(layout_);
  uint64_t chunk = kStagingBytes / info.bytesPerParticle;
  std::vector<char*> regions;
  std::vector<uint64_t> regionOffsets;
  uint64_t offset = 0;
  for (uint32_t bytes : elements) {
    regions.push_back(static_cast<char*>(staging.mapped()) + offset);
    regionOffsets.push_back(offset);
    offset += chunk * bytes;
  }
  if (options.spatialOrder && count_ > 1)
    order_ = std::make_shared<const std::vector<uint32_t>>(spatialOrder(set));
  const uint32_t* order = order_ ? order_->data() : nullptr;
  Progress progress("uploading particles to GPU", count_, " particles", options.progress);
  for (const ParticlePart& part : parts_) {
    for (uint64_t at = 0; at < part.count; at += chunk) {
      uint64_t n = std::min(chunk, part.count - at);
      parallelBlocksOn(0, n, 1u << 16, [&](uint64_t, uint64_t begin, uint64_t end) {
        fillStreams(layout_, set, order, part.first + at, begin, end, regions);
      });
      context.submitAndWait([&](VkCommandBuffer cmd) {
        uint64_t streamStart = 0; // byte where stream s of this part begins
        for (size_t s = 0; s < elements.size(); ++s) {
          VkBufferCopy copy{regionOffsets[s], streamStart + at * elements[s], n * elements[s]};
          gpu::vkCmdCopyBuffer(cmd, staging.handle(), part.data.handle(), 1, &copy);
          streamStart += part.count * elements[s];
        }
      });
      progress.advance(n);
    }
  }
}

} // namespace pointrast

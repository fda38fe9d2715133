// MMPLD writer: versions 1.0 and 1.3, one frame with one list (layout in particles_io.h). Every size is
// known up front, so the frame table is written with the header and the particles are streamed in chunks
// through PartialFile.
#include "io/io_util.h"
#include "io/particles/particles_io.h"

namespace pointrast::io {

using namespace detail;

namespace {

constexpr uint64_t kChunkParticles = uint64_t(1) << 16;

template <class T> void append(std::vector<uint8_t>& out, T v) {
  const size_t at = out.size();
  out.resize(at + sizeof v);
  storeLE(out.data() + at, v);
}

void appendBox(std::vector<uint8_t>& out, const Bounds& b) {
  // An empty set has no bounds; a zero box keeps the header finite.
  const Bounds box = b.empty() ? Bounds{glm::dvec3(0), glm::dvec3(0)} : b;
  for (const glm::dvec3& corner : {box.min, box.max})
    for (int a = 0; a < 3; ++a)
      append(out, static_cast<float>(corner[a]));
}

} // namespace

void writeMmpld(const std::filesystem::path& path, const ParticleSet& set, MmpldVersion version) {
  const uint64_t n = set.size();
  const bool perRadius = set.perParticleRadius(), perColor = set.perParticleColor();
  if (!perRadius && !(set.globalRadius >= 0 && std::isfinite(set.globalRadius)))
    fail(path, strFormat("cannot write the radius %g: MMPLD radii are non-negative numbers",
                         double(set.globalRadius)));
  const uint16_t fileVersion = version == MmpldVersion::V1_0 ? 100 : 103;
  const MmpldVertex vertex = perRadius ? MmpldVertex::FloatXyzr : MmpldVertex::FloatXyz;
  const MmpldColor color = perColor ? MmpldColor::Uint8Rgba : MmpldColor::None;
  const uint64_t stride = (perRadius ? 16 : 12) + (perColor ? 4 : 0);
  const Bounds spheres = sphereBounds(set);

  // The frame header and list header, then the file header, whose frame table needs their sizes.
  std::vector<uint8_t> frame;
  if (fileVersion >= 102) append(frame, 0.0f); // timestamp
  append<uint32_t>(frame, 1);                  // one list
  append(frame, static_cast<uint8_t>(vertex));
  append(frame, static_cast<uint8_t>(color));
  if (!perRadius) append(frame, set.globalRadius);
  if (!perColor) append(frame, set.globalColor); // packRgba is the R, G, B, A byte order MMPLD stores
  append<uint64_t>(frame, n);
  if (fileVersion >= 103) appendBox(frame, spheres);

  std::vector<uint8_t> header = {'M', 'M', 'P', 'L', 'D', 0};
  append(header, fileVersion);
  append<uint32_t>(header, 1); // frames
  appendBox(header, spheres);  // bounding box
  appendBox(header, spheres);  // clip box
  const uint64_t frameStart = header.size() + 2 * sizeof(uint64_t);
  append(header, frameStart);
  append(header, frameStart + frame.size() + n * stride);

  PartialFile out(path);
  out.write(header.data(), header.size());
  out.write(frame.data(), frame.size());
  std::vector<uint8_t> buffer(static_cast<size_t>(std::min(n, kChunkParticles) * stride));
  for (uint64_t first = 0; first < n; first += kChunkParticles) {
    const uint64_t count = std::min(kChunkParticles, n - first);
    uint8_t* p = buffer.data();
    for (uint64_t i = first; i < first + count; ++i) {
      const glm::dvec3 w = set.world(i);
      storeLE(p, static_cast<float>(w.x));
      storeLE(p + 4, static_cast<float>(w.y));
      storeLE(p + 8, static_cast<float>(w.z));
      p += 12;
      if (perRadius) {
        storeLE(p, set.radius[i]);
        p += 4;
      }
      if (perColor) {
        storeLE(p, set.colors[i]);
        p += 4;
      }
    }
    out.write(buffer.data(), static_cast<size_t>(count * stride));
  }
  out.commit();
}

} // namespace pointrast::io

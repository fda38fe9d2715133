// Reading and writing particle sets (spheres) as MMPLD, MegaMol's particle list data, versions 1.0-1.3.
// The reader treats the file as hostile, as the point readers do: every count and offset is checked
// against the frame it lies in (and so the file size) before anything is allocated, and a truncated or
// lying file throws InputError with one sentence naming the file.
//
// Layout (little endian), as MegaMol's MMPLDDataSource and MMPLDWriter and the VISUS mmpld library
// (github.com/UniStuttgart-VISUS/mmpld) read and write it:
//   file    "MMPLD\0", uint16 version (100 + minor: 100..103; 0 = not completely written, because
//           MegaMol's writer sets it last), uint32 frame count, float[6] bounding box and float[6] clip
//           box (min x y z, max x y z), uint64[frames + 1] frame offsets (the last: end of the last frame)
//   frame   1.2 and later: float timestamp; uint32 list count; the lists, back to back
//   list    uint8 vertex type, uint8 color type; float global radius (vertex types 1, 3, 4);
//           uint8[4] global RGBA (color type 0) or float[2] intensity range (color types 3 and 7);
//           uint64 particle count; 1.3: float[6] list bounding box; then count particles, each vertex
//           data then color data; 1.1 only: uint32 cluster count, uint64 n, n bytes of cluster data
//   vertex  0 none (the list has no data and is skipped), 1 FLOAT_XYZ, 2 FLOAT_XYZR, 3 SHORT_XYZ (int16),
//           4 DOUBLE_XYZ
//   color   0 none, 1 UINT8_RGB, 2 UINT8_RGBA, 3 FLOAT_I, 4 FLOAT_RGB, 5 FLOAT_RGBA, 6 USHORT_RGBA,
//           7 DOUBLE_I (its range is float too: a quirk of the format kept for compatibility)
// MegaMol's writer left the frame timestamp out of 1.3 files until its commit fc4e784, and many such
// files exist; their frames are recognised (the lists fill the frame exactly only without it) and read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "cloud/particles.h"

namespace pointrast::io {

enum class MmpldVertex : uint8_t { None, FloatXyz, FloatXyzr, ShortXyz, DoubleXyz };
enum class MmpldColor : uint8_t {
  None,
  Uint8Rgb,
  Uint8Rgba,
  FloatI,
  FloatRgb,
  FloatRgba,
  Uint16Rgba,
  DoubleI
};
// MegaMol's names: "FLOAT_XYZ", "UINT8_RGBA", ...
const char* mmpldVertexName(MmpldVertex vertex);
const char* mmpldColorName(MmpldColor color);

struct MmpldList {
  MmpldVertex vertex = MmpldVertex::None;
  MmpldColor color = MmpldColor::None;
  uint64_t count = 0;                       // as stated; a list without positions contributes nothing
  float globalRadius = 0;                   // vertex types without a per-particle radius
  uint32_t globalColor = 0;                 // color type none: packRgba of the file's RGBA bytes
  float intensityMin = 0, intensityMax = 0; // FLOAT_I, DOUBLE_I: mapped onto particleRamp()
  bool hasBounds = false;                   // 1.3: the list's bounding box, as stated
  Bounds bounds;
  uint64_t dataOffset = 0; // file offset of the first particle
  uint32_t stride = 0;     // bytes per particle (0 for vertex type none)

  bool hasPositions() const { return vertex != MmpldVertex::None; }
};

// The headers of a file and of one of its frames.
struct MmpldInfo {
  uint16_t version = 0; // 100..103
  uint32_t frames = 0;
  Bounds bbox, clipBox; // as the header states them (may be empty or NaN in odd files)
  uint32_t frame = 0;   // the frame described by the fields below
  uint64_t frameOffset = 0, frameBytes = 0;
  bool hasTimestamp = false; // 1.2 and later
  float timestamp = 0;
  bool timestampMissing = false; // a 1.3 frame written without its timestamp
  std::vector<MmpldList> lists;

  uint64_t particles() const; // over the lists with positions
};

struct MmpldReadOptions {
  uint32_t frame = 0;
  bool progress = true; // progress line on stderr when it is a terminal
};

// The file header and one frame's list headers, without reading particles. Throws InputError.
MmpldInfo probeMmpld(const std::filesystem::path& path, uint32_t frame = 0);

// Reads one frame into a ParticleSet: the particles of every list with positions, in file order. A
// radius or color is global when every list has the same global one, else it is stored per particle.
// Intensities are mapped over the list's range onto particleRamp() (over the values' own range when the
// stated one is empty or not finite). Particles with a NaN or infinite coordinate or a radius that is
// negative or not finite are dropped with one warning line. DOUBLE_XYZ lists are made relative to the
// center of their bounds (the set's origin), so far-off coordinates keep their precision; otherwise the
// origin is 0 and float positions are kept exactly. Memory: at most 20 B per particle, bounded by the
// file (the smallest particle record is 6 B). Throws InputError.
ParticleSet readMmpld(const std::filesystem::path& path, const MmpldReadOptions& options = {});

// Facts about one frame that take every particle, for `pointrast info`: the particles are streamed and
// nothing is kept. Same rules as readMmpld (dropped particles, origin). Throws InputError.
struct MmpldStats {
  uint64_t particles = 0, dropped = 0;
  Bounds centers;                     // world bounds of the kept particles' centers
  float radiusMin = 0, radiusMax = 0; // 0, 0 without particles
};
MmpldStats scanMmpld(const std::filesystem::path& path, const MmpldReadOptions& options = {});

enum class MmpldVersion { V1_0, V1_3 };

// Writes the set as one frame holding one list: FLOAT_XYZR with per-particle radii, else FLOAT_XYZ with
// the global radius; UINT8_RGBA with per-particle colors, else color type none with the global
// color. MMPLD stores float world coordinates, so positions are origin + xyz rounded once to float
// (exact when the origin is 0). The bounding and clip boxes are the spheres' bounds (centers +- radii);
// 1.3 adds a timestamp of 0 and the list's bounding box (the same). Written to "<path>.partial" and
// renamed when complete. Throws InputError for a radius that is negative or not finite, or a write error.
void writeMmpld(const std::filesystem::path& path, const ParticleSet& set,
                MmpldVersion version = MmpldVersion::V1_3);

} // namespace pointrast::io

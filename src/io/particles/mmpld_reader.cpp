// MMPLD reader, versions 1.0-1.3 (layout in particles_io.h). Headers are walked first and every count
// and offset checked against the frame, so the arrays are sized once from validated counts. The
// particle data of each list is then read in chunks of ~32 MiB (the next chunk read while the current
// one is decoded), and each chunk decoded in parallel blocks straight into the ParticleSet's arrays.
#include <atomic>
#include <optional>

#include "base/parallel.h"
#include "base/progress.h"
#include "io/formats.h"
#include "io/io_util.h"
#include "io/particles/particles_io.h"

namespace pointrast::io {

using namespace detail;

namespace {

constexpr uint64_t kFileHeaderBytes = 60; // magic 6, version 2, frames 4, two boxes 48
// A list header is at least vertex type, color type and count: 10 bytes.
constexpr uint64_t kMinListHeaderBytes = 10;
// Real files hold a few lists per frame (one per atom type); the cap bounds the header table a hostile
// frame of empty lists could make us build.
constexpr uint32_t kMaxLists = uint32_t(1) << 20;
constexpr uint64_t kDefaultChunkBytes = uint64_t(32) << 20;
std::atomic<uint64_t> gChunkBytes{kDefaultChunkBytes};
constexpr uint64_t kBlockParticles = uint64_t(1) << 16; // parallel work unit within a chunk

constexpr uint32_t kVertexBytes[] = {0, 12, 16, 6, 24};
constexpr uint32_t kColorBytes[] = {0, 3, 4, 4, 12, 16, 8, 8};

bool hasGlobalRadius(MmpldVertex v) {
  return v == MmpldVertex::FloatXyz || v == MmpldVertex::ShortXyz || v == MmpldVertex::DoubleXyz;
}
bool isIntensity(MmpldColor c) {
  return c == MmpldColor::FloatI || c == MmpldColor::DoubleI;
}

Bounds boxFromFloats(const uint8_t* p) {
  Bounds b;
  b.min = glm::dvec3(loadLE<float>(p), loadLE<float>(p + 4), loadLE<float>(p + 8));
  b.max = glm::dvec3(loadLE<float>(p + 12), loadLE<float>(p + 16), loadLE<float>(p + 20));
  return b;
}

// Reads a frame's headers front to back; every read is checked against the frame's end.
class FrameCursor {
public:
  FrameCursor(const InputFile& file, const MmpldInfo& info)
      : file_(file), in_(file, info.frameOffset, size_t(64) << 10), frame_(info.frame),
        end_(info.frameOffset + info.frameBytes) {}

  uint64_t position() const { return in_.position(); }
  uint64_t left() const { return end_ - in_.position(); }
  const uint8_t* take(size_t n, const std::string& what) {
    check(n, what);
    const uint8_t* p = in_.require(n, what.c_str());
    in_.consume(n);
    return p;
  }
  void skip(uint64_t n, const std::string& what) {
    check(n, what);
    in_.skip(n, what.c_str());
  }

private:
  void check(uint64_t n, const std::string& what) const {
    if (n > left())
      fail(file_.path(),
           strFormat("frame %u: %s runs past the end of the frame (byte %llu, the frame ends at %llu)",
                     frame_, what.c_str(), static_cast<unsigned long long>(position()),
                     static_cast<unsigned long long>(end_)));
  }
  const InputFile& file_;
  BufferedReader in_;
  uint32_t frame_;
  uint64_t end_;
};

// The lists of the frame in info, read with or without the 1.2+ timestamp. Returns the offset where the
// last list ends; throws InputError.
uint64_t walkFrame(const InputFile& file, MmpldInfo& info, bool timestamp) {
  const auto& path = file.path();
  FrameCursor in(file, info);
  info.lists.clear();
  info.hasTimestamp = timestamp;
  info.timestamp = timestamp ? loadLE<float>(in.take(4, "the timestamp")) : 0.0f;
  const uint32_t lists = loadLE<uint32_t>(in.take(4, "the list count"));
  if (lists > kMaxLists || lists * kMinListHeaderBytes > in.left())
    fail(path, strFormat("frame %u declares %u particle lists, more than its %llu bytes can hold%s",
                         info.frame, lists, static_cast<unsigned long long>(info.frameBytes),
                         lists > kMaxLists ? " (and more than the 1,048,576 this reader accepts)" : ""));
  for (uint32_t l = 0; l < lists; ++l) {
    const std::string what = strFormat("list %u", l);
    MmpldList list;
    const uint8_t* types = in.take(2, what + "'s header");
    if (types[0] > uint8_t(MmpldVertex::DoubleXyz))
      fail(path,
           strFormat("frame %u, list %u: unknown vertex type %u (MMPLD has 0-4)", info.frame, l, types[0]));
    if (types[1] > uint8_t(MmpldColor::DoubleI))
      fail(path,
           strFormat("frame %u, list %u: unknown color type %u (MMPLD has 0-7)", info.frame, l, types[1]));
    list.vertex = static_cast<MmpldVertex>(types[0]);
    list.color = static_cast<MmpldColor>(types[1]);
    if (hasGlobalRadius(list.vertex)) {
      list.globalRadius = loadLE<float>(in.take(4, what + "'s global radius"));
      if (!(list.globalRadius >= 0) || !std::isfinite(list.globalRadius))
        fail(path, strFormat("frame %u, list %u: the global radius %g is not a non-negative number",
                             info.frame, l, double(list.globalRadius)));
    }
    if (list.color == MmpldColor::None) {
      const uint8_t* c = in.take(4, what + "'s global color");
      list.globalColor = packRgba(c[0], c[1], c[2], c[3]);
    } else if (isIntensity(list.color)) {
      const uint8_t* r = in.take(8, what + "'s intensity range");
      list.intensityMin = loadLE<float>(r);
      list.intensityMax = loadLE<float>(r + 4);
    }
    list.count = loadLE<uint64_t>(in.take(8, what + "'s particle count"));
    if (info.version >= 103) {
      list.hasBounds = true;
      list.bounds = boxFromFloats(in.take(24, what + "'s bounding box"));
    }
    // MegaMol reads no data for a list without positions, whatever its color type (and writes such
    // lists with a count of 0).
    if (list.hasPositions()) {
      list.stride = kVertexBytes[types[0]] + kColorBytes[types[1]];
      if (list.count > in.left() / list.stride)
        fail(path,
             strFormat("frame %u, list %u: %llu particles of %u bytes do not fit in the %llu bytes left "
                       "in the frame (truncated or corrupt)",
                       info.frame, l, static_cast<unsigned long long>(list.count), list.stride,
                       static_cast<unsigned long long>(in.left())));
      list.dataOffset = in.position();
      in.skip(list.count * list.stride, what + "'s particles");
    }
    if (info.version == 101) {
      // MMPLD 1.1 follows each list with cluster information, which we skip.
      in.take(4, what + "'s cluster count");
      const uint64_t bytes = loadLE<uint64_t>(in.take(8, what + "'s cluster data size"));
      in.skip(bytes, what + "'s cluster data");
    }
    info.lists.push_back(list);
  }
  return in.position();
}

MmpldInfo readHeaders(const InputFile& file, uint32_t frame) {
  const auto& path = file.path();
  const uint64_t size = file.size();
  if (size < kFileHeaderBytes)
    fail(path, strFormat("not an MMPLD file: %llu bytes, shorter than the 60-byte header",
                         static_cast<unsigned long long>(size)));
  uint8_t h[kFileHeaderBytes];
  file.readAt(0, h, sizeof h);
  if (std::memcmp(h, "MMPLD\0", 6) != 0) fail(path, "not an MMPLD file (it does not start with \"MMPLD\")");
  MmpldInfo info;
  info.version = loadLE<uint16_t>(h + 6);
  if (info.version == 0)
    fail(path,
         "the MMPLD file was not completely written (version 0: MegaMol's writer sets the version last)");
  if (info.version < 100 || info.version > 103)
    fail(path, strFormat("MMPLD version %u.%u (%u) is not supported; this reader knows 1.0 to 1.3 (100-103)",
                         info.version / 100, info.version % 100, info.version));
  info.frames = loadLE<uint32_t>(h + 8);
  info.bbox = boxFromFloats(h + 12);
  info.clipBox = boxFromFloats(h + 36);
  if (info.frames == 0) fail(path, "the MMPLD file holds no frames");
  const uint64_t tableEnd = kFileHeaderBytes + 8 * (uint64_t(info.frames) + 1);
  if (tableEnd > size)
    fail(path, strFormat("the frame table of %u frames needs %llu bytes, but the file has %llu (truncated?)",
                         info.frames, static_cast<unsigned long long>(tableEnd),
                         static_cast<unsigned long long>(size)));
  if (frame >= info.frames)
    fail(path, strFormat("there is no frame %u: the file has %u frame%s (0 to %u)", frame, info.frames,
                         info.frames == 1 ? "" : "s", info.frames - 1));
  info.frame = frame;
  // The table's last entry is where the last frame ends: a file cut short (a partial download) is refused
  // even when the frame asked for is complete.
  uint8_t last[8];
  file.readAt(tableEnd - 8, last, sizeof last);
  if (loadLE<uint64_t>(last) > size)
    fail(path, strFormat("truncated: the frame table ends the file at byte %llu, but it has %llu bytes",
                         static_cast<unsigned long long>(loadLE<uint64_t>(last)),
                         static_cast<unsigned long long>(size)));
  uint8_t range[16];
  file.readAt(kFileHeaderBytes + 8 * uint64_t(frame), range, sizeof range);
  const uint64_t begin = loadLE<uint64_t>(range), end = loadLE<uint64_t>(range + 8);
  if (begin < tableEnd || begin > end || end > size)
    fail(path, strFormat("corrupt frame table: frame %u spans bytes %llu to %llu of a %llu-byte file whose "
                         "table ends at byte %llu",
                         frame, static_cast<unsigned long long>(begin), static_cast<unsigned long long>(end),
                         static_cast<unsigned long long>(size), static_cast<unsigned long long>(tableEnd)));
  info.frameOffset = begin;
  info.frameBytes = end - begin;

  if (info.version < 102) {
    walkFrame(file, info, false);
    return info;
  }
  // 1.2 and 1.3 have a timestamp, but MegaMol's writer left it out of 1.3 frames until its commit
  // fc4e784 (the reader's "HAZARD" note): when the lists read with the timestamp do not fill the frame
  // exactly but without it they do, the frame has none.
  std::optional<InputError> withTimestamp;
  try {
    if (walkFrame(file, info, true) == info.frameOffset + info.frameBytes || info.version == 102) return info;
  } catch (const InputError& e) {
    if (info.version == 102) throw;
    withTimestamp = e;
  }
  MmpldInfo without = info;
  try {
    if (walkFrame(file, without, false) == without.frameOffset + without.frameBytes) {
      without.timestampMissing = true;
      return without;
    }
  } catch (const InputError&) {
  }
  if (withTimestamp) throw *withTimestamp;
  return info; // lists followed by unused bytes
}

// ---- decoding ---------------------------------------------------------------------------------------

// How one list's particles become ParticleSet entries.
struct ListCodec {
  const MmpldList* list = nullptr;
  glm::dvec3 origin{0};
  double intensityScale = 0, intensityOffset = 0.5; // ramp position = value * scale + offset
};

// Where decoded particles go: radius and colors are null when the set does not store them per particle.
struct Target {
  float* xyz = nullptr;
  float* radius = nullptr;
  uint32_t* colors = nullptr;
  Target at(uint64_t i) const {
    return {xyz + 3 * i, radius ? radius + i : nullptr, colors ? colors + i : nullptr};
  }
};

struct BlockStats {
  uint64_t kept = 0;
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  float radiusMin = INFINITY, radiusMax = -INFINITY;
  void merge(const BlockStats& b) {
    kept += b.kept;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], b.lo[a]);
      hi[a] = std::max(hi[a], b.hi[a]);
    }
    radiusMin = std::min(radiusMin, b.radiusMin);
    radiusMax = std::max(radiusMax, b.radiusMax);
  }
};

inline uint32_t unorm8(float v) {
  return v > 0 ? static_cast<uint32_t>(std::min(v, 1.0f) * 255.0f + 0.5f) : 0; // NaN and negatives: 0
}
inline uint32_t unorm16to8(uint16_t v) {
  return (uint32_t(v) * 255 + 32767) / 65535; // nearest; MegaMol's c * 257 comes back exactly
}

uint32_t decodeColor(const uint8_t* c, const ListCodec& codec) {
  switch (codec.list->color) {
  case MmpldColor::None:
    break;
  case MmpldColor::Uint8Rgb:
    return packRgba(c[0], c[1], c[2]);
  case MmpldColor::Uint8Rgba:
    return packRgba(c[0], c[1], c[2], c[3]);
  case MmpldColor::FloatI:
    return particleRamp(loadLE<float>(c) * codec.intensityScale + codec.intensityOffset);
  case MmpldColor::DoubleI:
    return particleRamp(loadLE<double>(c) * codec.intensityScale + codec.intensityOffset);
  case MmpldColor::FloatRgb:
    return packRgba(unorm8(loadLE<float>(c)), unorm8(loadLE<float>(c + 4)), unorm8(loadLE<float>(c + 8)));
  case MmpldColor::FloatRgba:
    return packRgba(unorm8(loadLE<float>(c)), unorm8(loadLE<float>(c + 4)), unorm8(loadLE<float>(c + 8)),
                    unorm8(loadLE<float>(c + 12)));
  case MmpldColor::Uint16Rgba:
    return packRgba(unorm16to8(loadLE<uint16_t>(c)), unorm16to8(loadLE<uint16_t>(c + 2)),
                    unorm16to8(loadLE<uint16_t>(c + 4)), unorm16to8(loadLE<uint16_t>(c + 6)));
  }
  return codec.list->globalColor;
}

template <MmpldVertex V> glm::dvec3 loadPosition(const uint8_t* p) {
  if constexpr (V == MmpldVertex::DoubleXyz)
    return {loadLE<double>(p), loadLE<double>(p + 8), loadLE<double>(p + 16)};
  else if constexpr (V == MmpldVertex::ShortXyz)
    return {loadLE<int16_t>(p), loadLE<int16_t>(p + 2), loadLE<int16_t>(p + 4)};
  else
    return {loadLE<float>(p), loadLE<float>(p + 4), loadLE<float>(p + 8)};
}

// Decodes count particles into dst (packed: dropped particles leave no gap).
template <MmpldVertex V>
void decodeBlock(const uint8_t* src, uint64_t count, const ListCodec& codec, const Target& dst,
                 BlockStats& stats) {
  const MmpldList& list = *codec.list;
  const uint32_t stride = list.stride, colorOffset = kVertexBytes[uint8_t(V)];
  BlockStats s;
  for (uint64_t i = 0; i < count; ++i, src += stride) {
    const glm::dvec3 p = loadPosition<V>(src) - codec.origin;
    const float xyz[3] = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
    float r = list.globalRadius;
    if constexpr (V == MmpldVertex::FloatXyzr) r = loadLE<float>(src + 12);
    // Checked after the conversion to float, which turns doubles beyond its range into infinities.
    if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]) || !std::isfinite(r) ||
        !(r >= 0))
      continue;
    float* out = dst.xyz + 3 * s.kept;
    for (int a = 0; a < 3; ++a) {
      out[a] = xyz[a];
      s.lo[a] = std::min(s.lo[a], xyz[a]);
      s.hi[a] = std::max(s.hi[a], xyz[a]);
    }
    s.radiusMin = std::min(s.radiusMin, r);
    s.radiusMax = std::max(s.radiusMax, r);
    if (dst.radius) dst.radius[s.kept] = r;
    if (dst.colors) dst.colors[s.kept] = decodeColor(src + colorOffset, codec);
    ++s.kept;
  }
  stats = s;
}

void decodeBlockAny(const uint8_t* src, uint64_t count, const ListCodec& codec, const Target& dst,
                    BlockStats& stats) {
  switch (codec.list->vertex) {
  case MmpldVertex::FloatXyz:
    return decodeBlock<MmpldVertex::FloatXyz>(src, count, codec, dst, stats);
  case MmpldVertex::FloatXyzr:
    return decodeBlock<MmpldVertex::FloatXyzr>(src, count, codec, dst, stats);
  case MmpldVertex::ShortXyz:
    return decodeBlock<MmpldVertex::ShortXyz>(src, count, codec, dst, stats);
  case MmpldVertex::DoubleXyz:
    return decodeBlock<MmpldVertex::DoubleXyz>(src, count, codec, dst, stats);
  case MmpldVertex::None:
    break;
  }
}

// Moves n entries of a block that starts at `from` down to `to` (to < from), closing the gap that
// dropped particles left.
void moveBlock(const Target& dst, uint64_t from, uint64_t to, uint64_t n) {
  std::memmove(dst.xyz + 3 * to, dst.xyz + 3 * from, 3 * n * sizeof(float));
  if (dst.radius) std::memmove(dst.radius + to, dst.radius + from, n * sizeof(float));
  if (dst.colors) std::memmove(dst.colors + to, dst.colors + from, n * sizeof(uint32_t));
}

// Decodes every list into dst. append: the lists follow each other in dst (reading); otherwise every
// chunk is decoded to the start of dst, a scratch area of one chunk (scanning).
BlockStats decodeLists(const InputFile& file, const std::vector<ListCodec>& codecs, const Target& dst,
                       bool append, Progress* progress) {
  BlockStats total;
  uint64_t written = 0;
  std::vector<BlockStats> stats;
  for (const ListCodec& codec : codecs) {
    const MmpldList& list = *codec.list;
    forEachRecordChunk(
        file, list.dataOffset, list.count, list.stride, gChunkBytes,
        [&](const uint8_t* records, uint64_t, uint64_t count) {
          const Target chunk = dst.at(written);
          stats.assign((count + kBlockParticles - 1) / kBlockParticles, BlockStats{});
          parallelBlocks(count, kBlockParticles, [&](uint64_t block, uint64_t begin, uint64_t end) {
            decodeBlockAny(records + begin * list.stride, end - begin, codec, chunk.at(begin), stats[block]);
            if (progress) progress->advance(end - begin);
          });
          uint64_t kept = 0;
          for (uint64_t b = 0; b < stats.size(); ++b) {
            if (kept != b * kBlockParticles) moveBlock(chunk, b * kBlockParticles, kept, stats[b].kept);
            kept += stats[b].kept;
            total.merge(stats[b]);
          }
          if (append) written += kept;
        });
  }
  return total;
}

// Bounds of the finite positions of the DOUBLE_XYZ lists, whose center becomes the set's origin.
Bounds doubleBounds(const InputFile& file, const MmpldInfo& info) {
  Bounds bounds;
  for (const MmpldList& list : info.lists) {
    if (list.vertex != MmpldVertex::DoubleXyz) continue;
    forEachRecordChunk(file, list.dataOffset, list.count, list.stride, gChunkBytes,
                       [&](const uint8_t* records, uint64_t, uint64_t count) {
                         for (uint64_t i = 0; i < count; ++i) {
                           const glm::dvec3 p =
                               loadPosition<MmpldVertex::DoubleXyz>(records + i * list.stride);
                           if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
                             bounds.expand(p);
                         }
                       });
  }
  return bounds;
}

// The ramp mapping of an intensity list: over its stated range, or over its values' own range when the
// stated one is empty or not finite; constant values get the middle of the ramp.
void mapIntensity(const InputFile& file, ListCodec& codec) {
  const MmpldList& list = *codec.list;
  double lo = list.intensityMin, hi = list.intensityMax;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) {
    lo = INFINITY;
    hi = -INFINITY;
    const uint32_t at = kVertexBytes[uint8_t(list.vertex)];
    forEachRecordChunk(file, list.dataOffset, list.count, list.stride, gChunkBytes,
                       [&](const uint8_t* records, uint64_t, uint64_t count) {
                         for (uint64_t i = 0; i < count; ++i) {
                           const uint8_t* c = records + i * list.stride + at;
                           const double v =
                               list.color == MmpldColor::FloatI ? loadLE<float>(c) : loadLE<double>(c);
                           if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
                         }
                       });
  }
  if (hi > lo && std::isfinite(hi - lo)) {
    codec.intensityScale = 1.0 / (hi - lo);
    codec.intensityOffset = -lo / (hi - lo);
  }
}

// The lists that contribute particles, with their mappings, and the origin they share.
std::vector<ListCodec> prepareLists(const InputFile& file, const MmpldInfo& info, bool colors) {
  glm::dvec3 origin(0);
  for (const MmpldList& list : info.lists)
    if (list.vertex == MmpldVertex::DoubleXyz && list.count > 0) {
      const Bounds b = doubleBounds(file, info);
      if (!b.empty()) origin = b.center();
      break;
    }
  std::vector<ListCodec> codecs;
  for (const MmpldList& list : info.lists) {
    if (!list.hasPositions() || list.count == 0) continue;
    ListCodec codec;
    codec.list = &list;
    codec.origin = origin;
    if (colors && isIntensity(list.color)) mapIntensity(file, codec);
    codecs.push_back(codec);
  }
  return codecs;
}

void warnDropped(const std::filesystem::path& path, uint64_t dropped) {
  if (dropped)
    warn(path, strFormat("dropped %llu particles with NaN or infinite coordinates or an invalid radius",
                         static_cast<unsigned long long>(dropped)));
}

} // namespace

const char* mmpldVertexName(MmpldVertex vertex) {
  static const char* const kNames[] = {"NONE", "FLOAT_XYZ", "FLOAT_XYZR", "SHORT_XYZ", "DOUBLE_XYZ"};
  return kNames[uint8_t(vertex)];
}

const char* mmpldColorName(MmpldColor color) {
  static const char* const kNames[] = {"NONE",      "UINT8_RGB",  "UINT8_RGBA",  "FLOAT_I",
                                       "FLOAT_RGB", "FLOAT_RGBA", "USHORT_RGBA", "DOUBLE_I"};
  return kNames[uint8_t(color)];
}

uint64_t MmpldInfo::particles() const {
  uint64_t n = 0;
  for (const MmpldList& list : lists)
    if (list.hasPositions()) n += list.count;
  return n;
}

MmpldInfo probeMmpld(const std::filesystem::path& path, uint32_t frame) {
  InputFile file(path);
  return readHeaders(file, frame);
}

ParticleSet readMmpld(const std::filesystem::path& path, const MmpldReadOptions& options) {
  InputFile file(path);
  const MmpldInfo info = readHeaders(file, options.frame);
  ParticleSet set;
  set.source = path.filename().string();
  if (info.frames > 1) set.source += strFormat(", frame %u", info.frame);

  // A radius (color) is stored per particle unless every contributing list has the same global one.
  std::optional<float> radius;
  std::optional<uint32_t> color;
  bool perRadius = false, perColor = false;
  uint64_t n = 0;
  for (const MmpldList& list : info.lists) {
    if (!list.hasPositions() || list.count == 0) continue;
    n += list.count;
    if (!hasGlobalRadius(list.vertex))
      perRadius = true;
    else if (!radius)
      radius = list.globalRadius;
    else
      perRadius |= *radius != list.globalRadius;
    if (list.color != MmpldColor::None)
      perColor = true;
    else if (!color)
      color = list.globalColor;
    else
      perColor |= *color != list.globalColor;
  }
  if (radius) set.globalRadius = *radius;
  if (color) set.globalColor = *color;
  // n particles were checked to lie in the frame at >= 6 bytes each: these allocations are bounded by the
  // file, at most 20 B per 6 B record.
  set.xyz.resize(3 * n);
  if (perRadius) set.radius.resize(n);
  if (perColor) set.colors.resize(n);

  const std::vector<ListCodec> codecs = prepareLists(file, info, perColor);
  if (!codecs.empty()) set.origin = codecs.front().origin;
  std::optional<Progress> progress;
  if (options.progress) progress.emplace("reading " + path.filename().string(), n, " particles");
  const Target dst{set.xyz.data(), perRadius ? set.radius.data() : nullptr,
                   perColor ? set.colors.data() : nullptr};
  const BlockStats stats = decodeLists(file, codecs, dst, true, progress ? &*progress : nullptr);
  if (progress) progress->finish();

  warnDropped(path, n - stats.kept);
  set.xyz.resize(3 * stats.kept);
  if (perRadius) set.radius.resize(stats.kept);
  if (perColor) set.colors.resize(stats.kept);
  if (stats.kept > 0) {
    set.bounds.expand(set.origin + glm::dvec3(stats.lo[0], stats.lo[1], stats.lo[2]));
    set.bounds.expand(set.origin + glm::dvec3(stats.hi[0], stats.hi[1], stats.hi[2]));
  }
  return set;
}

MmpldStats scanMmpld(const std::filesystem::path& path, const MmpldReadOptions& options) {
  InputFile file(path);
  const MmpldInfo info = readHeaders(file, options.frame);
  const std::vector<ListCodec> codecs = prepareLists(file, info, false);
  uint64_t n = 0, scratch = 0;
  for (const ListCodec& codec : codecs) {
    n += codec.list->count;
    scratch = std::max(scratch,
                       std::min(codec.list->count, std::max<uint64_t>(1, gChunkBytes / codec.list->stride)));
  }
  std::vector<float> xyz(3 * scratch);
  std::optional<Progress> progress;
  if (options.progress) progress.emplace("scanning " + path.filename().string(), n, " particles");
  const BlockStats stats =
      decodeLists(file, codecs, Target{xyz.data()}, false, progress ? &*progress : nullptr);
  if (progress) progress->finish();

  MmpldStats out;
  out.particles = stats.kept;
  out.dropped = n - stats.kept;
  if (stats.kept > 0) {
    const glm::dvec3 origin = codecs.front().origin;
    out.centers.expand(origin + glm::dvec3(stats.lo[0], stats.lo[1], stats.lo[2]));
    out.centers.expand(origin + glm::dvec3(stats.hi[0], stats.hi[1], stats.hi[2]));
    out.radiusMin = stats.radiusMin;
    out.radiusMax = stats.radiusMax;
  }
  return out;
}

namespace detail {
void setMmpldChunkBytes(uint64_t bytes) {
  gChunkBytes = bytes ? bytes : kDefaultChunkBytes;
}
} // namespace detail

} // namespace pointrast::io

// LAS and LAZ writers (ASPRS LAS 1.4 R15; LAZ through las/laz_encoder.h). LasFileWriter writes raw
// records under a given header and VLRs: uncompressed after the VLRs, or as LASzip chunks after the
// LASzip VLR, with the chunk table at the end; the header, whose counts and bounds depend on every
// point, is written last over a placeholder, through PartialFile. LasRecordWriter builds LAS 1.2 point
// format 2/3 or 1.4 format 7 records from PointRecords and writes them through a LasFileWriter.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>
#include <optional>
#include <unordered_map>

#include "base/parallel.h"
#include "base/progress.h"
#include "io/copc_ept/copc.h"
#include "io/copc_ept/copc_chunks.h"
#include "io/las/las_filter.h"
#include "io/las/las_format.h"
#include "io/las/laz_encoder.h"
#include "io/las/laz_reader.h"
#include "io/writer.h"

namespace pointrast::io {

using namespace detail;

namespace {

constexpr uint64_t kChunkPoints = uint64_t(1) << 16;

struct FlavorInfo {
  uint8_t minor;
  int pointFormat;
  uint64_t headerSize;
};

FlavorInfo flavorInfo(LasFlavor flavor) {
  switch (flavor) {
  case LasFlavor::Las12Pf2:
    return {2, 2, las::kHeaderSize12};
  case LasFlavor::Las12Pf3:
    return {2, 3, las::kHeaderSize12};
  case LasFlavor::Las14Pf7:
    return {4, 7, las::kHeaderSize14};
  }
  return {2, 3, las::kHeaderSize12};
}

} // namespace

bool isLazPath(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".laz";
}

// ---- LasFileWriter ----------------------------------------------------------------------------------------

namespace {

// LAZ chunks encoded at once: a few per core, so every core has work while memory stays a few chunks
// of records per core.
constexpr uint64_t kChunksPerThread = 2;

} // namespace

struct LasFileWriter::State {
  std::filesystem::path path;
  LasFileSetup setup;
  std::optional<PartialFile> out;
  std::vector<uint8_t> prefix; // header and VLRs as written at commit
  uint64_t pointOffset = 0;
  uint64_t count = 0;
  int32_t qmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, qmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  std::array<uint64_t, 15> byReturn{};
  // LAZ
  std::optional<laz::Layout> layout;
  std::vector<uint8_t> pending;        // records of the chunks not yet encoded
  std::vector<uint64_t> pendingCounts; // their chunk sizes (the last one may be partial)
  std::vector<laz::Chunk> table;
  uint64_t chunkBytes = 0;

  void account(const uint8_t* records, uint64_t n);
  void encodePending(bool all);
};

void LasFileWriter::State::account(const uint8_t* records, uint64_t n) {
  const size_t rl = setup.recordLength;
  const bool extended = las::isExtended(setup.pointFormat);
  for (uint64_t k = 0; k < n; ++k) {
    const uint8_t* r = records + k * rl;
    for (int a = 0; a < 3; ++a) {
      const int32_t q = loadLE<int32_t>(r + 4 * a);
      qmin[a] = std::min(qmin[a], q);
      qmax[a] = std::max(qmax[a], q);
    }
    const unsigned rn = extended ? (r[14] & 0x0F) : (r[14] & 0x07);
    if (rn >= 1 && rn <= 15) ++byReturn[rn - 1];
  }
  count += n;
}

void LasFileWriter::State::encodePending(bool all) {
  const unsigned threads = hardwareThreads();
  const size_t rl = setup.recordLength;
  size_t ready = pendingCounts.size();
  // A partial last chunk of fixed size waits for more records unless this is the end.
  if (!all && !layout->variableChunks() && ready > 0 && pendingCounts.back() < setup.chunkSize) --ready;
  if (ready == 0 || (!all && ready < threads * kChunksPerThread)) return;
  const std::vector<uint64_t> counts(pendingCounts.begin(), pendingCounts.begin() + ptrdiff_t(ready));
  const std::vector<std::vector<uint8_t>> chunks = laz::encodeChunks(*layout, pending.data(), counts);
  uint64_t used = 0;
  for (size_t i = 0; i < chunks.size(); ++i) {
    out->write(chunks[i].data(), chunks[i].size());
    table.push_back({0, chunks[i].size(), 0, counts[i]});
    chunkBytes += chunks[i].size();
    used += counts[i];
  }
  pending.erase(pending.begin(), pending.begin() + ptrdiff_t(used * rl));
  pendingCounts.erase(pendingCounts.begin(), pendingCounts.begin() + ptrdiff_t(ready));
}

LasFileWriter::LasFileWriter(const std::filesystem::path& path, LasFileSetup setup)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.path = path;
  s.setup = std::move(setup);
  const LasFileSetup& st = s.setup;
  if (st.header.size() < las::kHeaderSize12 || st.header.size() > UINT16_MAX)
    fail(path, "the LAS header to write has a wrong size");
  if (st.pointFormat < 0 || st.pointFormat > las::kMaxPointFormat ||
      st.recordLength < las::kRecordSize[size_t(st.pointFormat)])
    fail(path, strFormat("point format %d cannot have %u-byte records", st.pointFormat, st.recordLength));
  const uint8_t minor = st.header[las::kVersionMinor];
  if (las::isExtended(st.pointFormat) && minor < 4)
    fail(path, strFormat("point format %d needs LAS 1.4, the header says 1.%u", st.pointFormat, minor));
  if ((!st.evlrs.empty() && minor < 4) || (minor >= 4 && st.header.size() < las::kHeaderSize14))
    fail(path, "the LAS header to write is too short for its version");
  for (int a = 0; a < 3; ++a) {
    const double scale = loadLE<double>(st.header.data() + las::kScale + 8 * a);
    const double offset = loadLE<double>(st.header.data() + las::kOffset + 8 * a);
    if (!std::isfinite(scale) || scale == 0.0 || !std::isfinite(offset))
      fail(path, "the scale/offset (NaN, infinite or a zero scale) cannot be written as LAS");
  }
  s.prefix = st.header;
  uint32_t vlrCount = 0;
  for (const std::vector<uint8_t>& v : st.vlrs) {
    if (v.size() < las::kVlrHeaderSize || v.size() - las::kVlrHeaderSize > UINT16_MAX)
      fail(path, "a VLR to write has a wrong size");
    s.prefix.insert(s.prefix.end(), v.begin(), v.end());
    ++vlrCount;
  }
  if (st.laz) {
    if (!laz::canEncodePointFormat(st.pointFormat))
      fail(path,
           strFormat("point format %d cannot be written as LAZ (formats 0-3 and 6-8 can)", st.pointFormat));
    if (st.chunkSize == 0) fail(path, "a LAZ chunk size of 0 points");
    s.layout = laz::encoderLayout(st.pointFormat, st.recordLength, st.chunkSize);
    const std::vector<uint8_t> vlr =
        las::vlrBytes("laszip encoded", 22204, "LAZ by pointrast", laz::laszipVlrPayload(*s.layout));
    s.prefix.insert(s.prefix.end(), vlr.begin(), vlr.end());
    ++vlrCount;
  }
  if (s.prefix.size() > UINT32_MAX) fail(path, "the VLRs are too large for a LAS header");
  s.pointOffset = s.prefix.size();
  storeLE<uint32_t>(s.prefix.data() + las::kPointOffset, uint32_t(s.pointOffset));
  storeLE<uint32_t>(s.prefix.data() + las::kVlrCount, vlrCount);
  s.out.emplace(path);
  const std::vector<uint8_t> placeholder(s.prefix.size() + (st.laz ? 8 : 0), 0);
  s.out->write(placeholder.data(), placeholder.size());
}

LasFileWriter::~LasFileWriter() = default;

void LasFileWriter::write(const uint8_t* records, uint64_t count) {
  State& s = *state_;
  const size_t rl = s.setup.recordLength;
  if (s.setup.header[las::kVersionMinor] < 4 && s.count + count > UINT32_MAX)
    fail(s.path, "more than 4294967295 points do not fit in LAS 1.0-1.3; write LAS 1.4");
  if (!s.layout) {
    s.account(records, count);
    s.out->write(records, size_t(count * rl));
    return;
  }
  if (s.layout->variableChunks()) {
    writeChunk(records, count);
    return;
  }
  s.account(records, count);
  for (uint64_t done = 0; done < count;) {
    if (s.pendingCounts.empty() || s.pendingCounts.back() == s.setup.chunkSize) s.pendingCounts.push_back(0);
    const uint64_t n = std::min<uint64_t>(count - done, s.setup.chunkSize - s.pendingCounts.back());
    s.pending.insert(s.pending.end(), records + done * rl, records + (done + n) * rl);
    s.pendingCounts.back() += n;
    done += n;
    s.encodePending(false);
  }
}

void LasFileWriter::writeChunk(const uint8_t* records, uint64_t count) {
  State& s = *state_;
  if (!s.layout || !s.layout->variableChunks()) {
    write(records, count);
    return;
  }
  if (count == 0) return;
  if (count > UINT32_MAX) fail(s.path, "a LAZ chunk of more than 4294967295 points");
  s.account(records, count);
  s.pending.insert(s.pending.end(), records, records + count * s.setup.recordLength);
  s.pendingCounts.push_back(count);
  s.encodePending(false);
}

uint64_t LasFileWriter::pointsWritten() const {
  return state_->count;
}

void LasFileWriter::commit() {
  State& s = *state_;
  const LasFileSetup& st = s.setup;
  uint8_t* h = s.prefix.data();
  uint64_t end = s.pointOffset + s.count * st.recordLength;
  if (s.layout) {
    s.encodePending(true);
    const uint64_t tableOffset = s.pointOffset + 8 + s.chunkBytes;
    const std::vector<uint8_t> table = laz::encodeChunkTable(s.table, s.layout->variableChunks());
    s.out->write(table.data(), table.size());
    uint8_t offset[8];
    storeLE<int64_t>(offset, int64_t(tableOffset));
    s.out->writeAt(s.pointOffset, offset, 8);
    end = tableOffset + table.size();
  }
  for (const std::vector<uint8_t>& e : st.evlrs)
    s.out->write(e.data(), e.size());

  const bool extended = las::isExtended(st.pointFormat);
  const uint8_t minor = h[las::kVersionMinor];
  h[las::kPointFormat] = static_cast<uint8_t>(st.pointFormat | (s.layout ? 0x80 : 0));
  storeLE<uint16_t>(h + las::kRecordLength, st.recordLength);
  // The legacy fields hold formats 0-5 up to 2^32 - 1 points; formats 6-10 leave them 0 (R15 2.4).
  const bool legacy = !extended && s.count <= UINT32_MAX;
  storeLE<uint32_t>(h + las::kLegacyCount, legacy ? uint32_t(s.count) : 0);
  for (int i = 0; i < 5; ++i)
    storeLE<uint32_t>(h + las::kLegacyByReturn + 4 * i, legacy ? uint32_t(s.byReturn[size_t(i)]) : 0);
  glm::dvec3 scale, offset;
  for (int a = 0; a < 3; ++a) {
    scale[a] = loadLE<double>(h + las::kScale + 8 * a);
    offset[a] = loadLE<double>(h + las::kOffset + 8 * a);
  }
  Bounds bounds;
  if (s.count > 0)
    bounds = boundsFromQuantized(s.qmin, s.qmax, scale, offset);
  else
    bounds.min = bounds.max = glm::dvec3(0);
  for (int a = 0; a < 3; ++a) {
    storeLE<double>(h + las::kMaxX + 16 * a, bounds.max[a]);
    storeLE<double>(h + las::kMaxX + 16 * a + 8, bounds.min[a]);
  }
  if (minor >= 3 && st.header.size() >= las::kHeaderSize13 && st.pointFormat != 4 && st.pointFormat != 5 &&
      st.pointFormat != 9 && st.pointFormat != 10)
    storeLE<uint64_t>(h + las::kWaveformStart, 0);
  if (minor >= 4) {
    storeLE<uint64_t>(h + las::kEvlrStart, st.evlrs.empty() ? 0 : end);
    storeLE<uint32_t>(h + las::kEvlrCount, uint32_t(st.evlrs.size()));
    storeLE<uint64_t>(h + las::kCount64, s.count);
    for (int i = 0; i < 15; ++i)
      storeLE<uint64_t>(h + las::kByReturn64 + 8 * i, s.byReturn[size_t(i)]);
  }
  s.out->writeAt(0, s.prefix.data(), s.prefix.size());
  s.out->commit();
}

// ---- convertLasFile ---------------------------------------------------------------------------------------

namespace {

// The EVLRs of a LAS 1.4 file, each its 60-byte header and payload; COPC's are left out.
std::vector<std::vector<uint8_t>> readEvlrs(const InputFile& file, const LasHeader& hd) {
  std::vector<std::vector<uint8_t>> out;
  uint64_t at = hd.evlrStart;
  constexpr uint64_t kEvlrHeader = 60;
  for (uint32_t i = 0; i < hd.evlrCount && hd.evlrStart != 0; ++i) {
    if (at > file.size() || file.size() - at < kEvlrHeader)
      fail(file.path(), strFormat("EVLR %u of %u lies past the end of the file", i + 1, hd.evlrCount));
    std::vector<uint8_t> e(kEvlrHeader);
    file.readAt(at, e.data(), e.size());
    const uint64_t length = loadLE<uint64_t>(e.data() + 20);
    if (length > file.size() - at - kEvlrHeader)
      fail(file.path(), strFormat("EVLR %u of %u runs past the end of the file", i + 1, hd.evlrCount));
    const std::string userId(reinterpret_cast<const char*>(e.data() + 2),
                             strnlen(reinterpret_cast<const char*>(e.data() + 2), 16));
    if (userId != "copc") {
      e.resize(kEvlrHeader + length);
      file.readAt(at + kEvlrHeader, e.data() + kEvlrHeader, size_t(length));
      out.push_back(std::move(e));
    }
    at += kEvlrHeader + length;
  }
  return out;
}

// One record from point format `from` (0-3, 6-8; a waveform format's record read as its base format's,
// the packet skipped) to `to`, extra bytes copied. Returns what the target format cannot hold (empty when
// nothing is lost). Layouts, R15 section 2.6: formats 0-5 keep return number and count in 3 bits each,
// classification in the low 5 bits of byte 15 with the synthetic, key-point and withheld flags above,
// the scan angle as whole degrees (int8 at 16); formats 6-10 use 4-bit returns, byte 15 for the four
// flags, scanner channel, scan direction and edge, byte 16 for the class and an int16 scan angle in
// 0.006 degree steps.
struct RecordTranscoder {
  int from, to;
  uint16_t fromExtraAt, toLength, extra;

  const char* operator()(const uint8_t* in, uint8_t* out) const {
    const bool fromExt = las::isExtended(from), toExt = las::isExtended(to);
    if (from == to) { // a waveform format without its packets
      std::memcpy(out, in, las::kRecordSize[size_t(to)]);
      std::memcpy(out + las::kRecordSize[size_t(to)], in + fromExtraAt, extra);
      return nullptr;
    }
    std::memset(out, 0, toLength);
    std::memcpy(out, in, 14); // X, Y, Z, intensity
    unsigned rn, nr, flags, channel, dir, edge, cls, user, source;
    int angle; // 0.006 degree steps
    if (fromExt) {
      rn = in[14] & 15, nr = in[14] >> 4;
      flags = in[15] & 15, channel = (in[15] >> 4) & 3, dir = (in[15] >> 6) & 1, edge = in[15] >> 7;
      cls = in[16], user = in[17], angle = loadLE<int16_t>(in + 18), source = loadLE<uint16_t>(in + 20);
    } else {
      rn = in[14] & 7, nr = (in[14] >> 3) & 7, dir = (in[14] >> 6) & 1, edge = in[14] >> 7;
      cls = in[15] & 31, flags = in[15] >> 5, channel = 0;
      user = in[17], angle = int(std::lround(int8_t(in[16]) / 0.006)), source = loadLE<uint16_t>(in + 18);
    }
    const int gpsFrom = fromExt ? 22 : (from == 1 || from == 3) ? 20 : -1;
    const int gpsTo = toExt ? 22 : (to == 1 || to == 3) ? 20 : -1;
    const int rgbFrom = las::kRgbOffset[size_t(from)], rgbTo = las::kRgbOffset[size_t(to)];
    if (toExt) {
      out[14] = uint8_t(rn | (nr << 4));
      out[15] = uint8_t(flags | (channel << 4) | (dir << 6) | (edge << 7));
      out[16] = uint8_t(cls);
      out[17] = uint8_t(user);
      storeLE<int16_t>(out + 18, int16_t(angle));
      storeLE<uint16_t>(out + 20, uint16_t(source));
    } else {
      if (rn > 7 || nr > 7) return "return numbers above 7";
      if (cls > 31) return "classes above 31";
      if (flags & 8) return "the overlap flag";
      if (channel != 0) return "scanner channels";
      const long rank = std::lround(angle * 0.006);
      if (std::lround(double(rank) / 0.006) != angle || rank < -128 || rank > 127)
        return "scan angles finer than a degree";
      out[14] = uint8_t(rn | (nr << 3) | (dir << 6) | (edge << 7));
      out[15] = uint8_t(cls | (flags << 5));
      out[16] = uint8_t(int8_t(rank));
      out[17] = uint8_t(user);
      storeLE<uint16_t>(out + 18, uint16_t(source));
    }
    auto zero = [](const uint8_t* p, size_t n) {
      for (size_t i = 0; i < n; ++i)
        if (p[i]) return false;
      return true;
    };
    if (gpsFrom >= 0 && gpsTo >= 0) std::memcpy(out + gpsTo, in + gpsFrom, 8);
    if (gpsFrom >= 0 && gpsTo < 0 && !zero(in + gpsFrom, 8)) return "GPS times";
    if (rgbFrom >= 0 && rgbTo >= 0) std::memcpy(out + rgbTo, in + rgbFrom, 6);
    if (rgbFrom >= 0 && rgbTo < 0 && !zero(in + rgbFrom, 6)) return "colors";
    if (from == 8 && to == 8) std::memcpy(out + 36, in + 36, 2);
    if (from == 8 && to != 8 && !zero(in + 36, 2)) return "near infrared";
    std::memcpy(out + las::kRecordSize[size_t(to)], in + fromExtraAt, extra);
    return nullptr;
  }
};

} // namespace

uint64_t convertLasFile(const std::filesystem::path& in, const std::filesystem::path& outPath,
                        const LasConvertOptions& options) {
  InputFile file(in);
  const bool compressed = lasLooksCompressed(file);
  std::optional<laz::LazFile> lazFile;
  LasHeader hd;
  if (compressed) {
    lazFile = laz::openLaz(file);
    hd = lazFile->header;
  } else {
    hd = readLasHeader(file);
  }
  const int baseFormat = las::withoutWaveform(hd.pointFormat);
  const bool dropWaves = baseFormat != hd.pointFormat;
  if (dropWaves && !options.dropWaveforms)
    fail(in, strFormat("point format %d carries waveform packets, which the output would lose; "
                       "--drop-waveforms writes the points without them (format %d)",
                       hd.pointFormat, baseFormat));
  int format = options.pointFormat >= 0 ? options.pointFormat : baseFormat;
  if (options.pointFormat < 0 && options.versionMinor >= 0) {
    // The version's format with the input's attributes: 1.4 writes 6-8, 1.0-1.2 writes 0-3.
    static const int kTo14[] = {6, 6, 7, 7, 6, 7, 6, 7, 8, 6, 8};
    static const int kTo12[] = {0, 1, 2, 3, 1, 3, 1, 3, 3, 1, 3};
    format = options.versionMinor >= 4 ? kTo14[size_t(baseFormat)] : kTo12[size_t(baseFormat)];
  }
  if (!laz::canEncodePointFormat(format))
    fail(outPath, strFormat("point format %d cannot be written (formats 0-3 and 6-8 can)", format));
  const uint16_t baseBytes = las::kRecordSize[size_t(format)];
  const uint16_t inBase = las::kRecordSize[size_t(hd.pointFormat)];
  if (hd.recordLength < inBase)
    fail(in, strFormat("%u-byte records are too short for point format %d", hd.recordLength, hd.pointFormat));
  const uint16_t extraBytes = uint16_t(hd.recordLength - inBase);
  const bool transcode = format != hd.pointFormat;
  const RecordTranscoder transcoder{baseFormat, format, inBase, uint16_t(baseBytes + extraBytes), extraBytes};

  LasFileSetup setup;
  setup.header.resize(hd.headerSize);
  file.readAt(0, setup.header.data(), setup.header.size());
  if (options.versionMinor >= 0 && options.versionMinor < 4 && las::isExtended(format))
    fail(outPath, strFormat("point format %d needs LAS 1.4", format));
  if (options.versionMinor >= 0 && options.versionMinor < 4 && hd.versionMinor >= 3) {
    // Down to LAS 1.0-1.2: the header ends at 227 bytes, so nothing may need the 1.3-1.4 fields.
    if (hd.evlrCount > 0) fail(in, "its EVLRs cannot be written to LAS 1.2");
    setup.header.resize(las::kHeaderSize12);
    setup.header[las::kVersionMinor] = uint8_t(options.versionMinor);
    storeLE<uint16_t>(setup.header.data() + las::kHeaderSizeField, uint16_t(las::kHeaderSize12));
  }
  if ((las::isExtended(format) || options.versionMinor == 4) && hd.versionMinor < 4) {
    // Up to LAS 1.4 (formats 6-10 need it): the 1.0-1.3 fields stay, the 1.4 ones start at zero; for
    // formats 6-10 bit 4 of the global encoding says the CRS, if any, is WKT, as R15 requires.
    setup.header.resize(std::max<size_t>(setup.header.size(), las::kHeaderSize14), 0);
    std::fill(setup.header.begin() + las::kWaveformStart, setup.header.begin() + las::kHeaderSize14, 0);
    setup.header[las::kVersionMinor] = 4;
    storeLE<uint16_t>(setup.header.data() + las::kHeaderSizeField, uint16_t(setup.header.size()));
    const uint16_t ge = loadLE<uint16_t>(setup.header.data() + las::kGlobalEncoding);
    if (las::isExtended(format))
      storeLE<uint16_t>(setup.header.data() + las::kGlobalEncoding, uint16_t(ge | 0x10));
  }
  setup.pointFormat = format;
  setup.recordLength = uint16_t(baseBytes + extraBytes);
  setup.laz = isLazPath(outPath);
  setup.chunkSize = options.chunkSize;
  if (dropWaves) {
    // Global encoding bits 1 and 2: waveform data packets internal / external.
    const uint16_t ge = loadLE<uint16_t>(setup.header.data() + las::kGlobalEncoding);
    storeLE<uint16_t>(setup.header.data() + las::kGlobalEncoding, uint16_t(ge & ~0x6u));
  }
  for (const LasVlr& vlr : hd.vlrs) {
    if (vlr.userId == "laszip encoded" || vlr.userId == "copc") continue;
    // Waveform packet descriptors (LASF_Spec 100-354) describe packets that are no longer there.
    if (dropWaves && vlr.userId == "LASF_Spec" && vlr.recordId >= 100 && vlr.recordId < 355) continue;
    std::vector<uint8_t> v(las::kVlrHeaderSize + vlr.length);
    file.readAt(vlr.dataOffset - las::kVlrHeaderSize, v.data(), v.size());
    setup.vlrs.push_back(std::move(v));
  }
  if (setup.header[las::kVersionMinor] >= 4) setup.evlrs = readEvlrs(file, hd);

  const PointFilter* filter = options.filter && options.filter->active() ? options.filter : nullptr;
  if (filter) requireFilterAttributes(*filter, lasFilterFields(hd.pointFormat), in.filename().string());
  PointFilter attributesOnly; // for the points of chunks the clip keeps as a whole
  if (filter) {
    attributesOnly = *filter;
    attributesOnly.boxes.clear();
    attributesOnly.orientedBoxes.clear();
    attributesOnly.polygons.clear();
  }
  // A COPC file's chunks are octree nodes: with a clip, the chunks whose cube it rejects are not decoded.
  std::vector<BoxVerdict> verdicts;
  uint64_t skippedPoints = 0;
  if (filter && filter->hasClip() && compressed && hasCopcInfoVlr(file)) {
    const std::vector<CopcChunkCube> cubes = copcChunkCubes(in);
    std::unordered_map<uint64_t, Bounds> cubeAt;
    for (const CopcChunkCube& c : cubes)
      cubeAt[c.offset] = c.cube;
    std::vector<laz::Chunk> kept;
    for (const laz::Chunk& chunk : lazFile->chunks) {
      const auto it = cubeAt.find(chunk.offset);
      const BoxVerdict v = it == cubeAt.end() ? BoxVerdict::Some : clipVerdict(*filter, it->second);
      if (options.nodeStats) {
        ++options.nodeStats->nodes;
        options.nodeStats->skipped += v == BoxVerdict::None;
      }
      if (v == BoxVerdict::None) {
        skippedPoints += chunk.pointCount;
        continue;
      }
      kept.push_back(chunk);
      verdicts.push_back(v);
    }
    lazFile->chunks = std::move(kept);
  }

  std::optional<LasFileWriter> writer;
  if (!outPath.empty()) writer.emplace(outPath, std::move(setup));
  std::optional<Progress> line;
  if (options.progress) line.emplace("converting " + in.filename().string(), hd.pointCount);
  if (line) line->advance(skippedPoints);
  std::vector<uint8_t> converted, selected;
  uint64_t done = 0, written = 0;
  auto deliver = [&](const uint8_t* records, uint64_t n, BoxVerdict verdict) {
    const uint64_t read = n;
    if (filter || options.keep) {
      const PointFilter& test = verdict == BoxVerdict::All ? attributesOnly : *filter;
      selected.resize(size_t(n) * hd.recordLength);
      uint64_t k = 0;
      for (uint64_t i = 0; i < n; ++i) {
        const uint8_t* r = records + i * hd.recordLength;
        const FilterPoint p = lasFilterPoint(r, hd.pointFormat, hd.scale, hd.offset);
        if (filter && !passes(test, p)) continue;
        if (options.keep && !options.keep(r, p)) continue;
        std::memcpy(selected.data() + k++ * hd.recordLength, r, hd.recordLength);
      }
      records = selected.data();
      n = k;
    }
    if (transcode) {
      const size_t outLength = size_t(baseBytes) + extraBytes;
      converted.resize(size_t(n) * outLength);
      for (uint64_t k = 0; k < n; ++k)
        if (const char* lost = transcoder(records + k * hd.recordLength, converted.data() + k * outLength))
          fail(in, strFormat("point %llu has %s, which point format %d cannot hold",
                             static_cast<unsigned long long>(done + k + 1), lost, format));
      records = converted.data();
    }
    done += n;
    written += n;
    if (writer) writer->write(records, n);
    if (line) line->advance(read);
  };
  if (compressed) {
    detail::decodeLazInWindows(file, *lazFile, detail::lazThreads(),
                               [&](size_t first, std::vector<std::vector<uint8_t>>& records) {
                                 for (size_t k = 0; k < records.size(); ++k)
                                   deliver(records[k].data(), records[k].size() / hd.recordLength,
                                           verdicts.empty() ? BoxVerdict::Some : verdicts[first + k]);
                               });
  } else {
    forEachRecordChunk(
        file, hd.pointOffset, hd.pointCount, hd.recordLength, lasChunkBytes(),
        [&](const uint8_t* records, uint64_t, uint64_t n) { deliver(records, n, BoxVerdict::Some); });
  }
  if (line) line->finish();
  if (writer) writer->commit();
  return written;
}

// ---- LasRecordWriter --------------------------------------------------------------------------------------

struct LasRecordWriter::State {
  State(const std::filesystem::path& p, LasFlavor flavor) : f(flavorInfo(flavor)), path(p) {}

  FlavorInfo f;
  std::filesystem::path path;
  std::optional<LasFileWriter> out;
  uint16_t recordLength = 0;
  RecordFields fields;
  std::vector<uint8_t> buffer;

  void encode(const PointRecord* records, size_t n);
  std::vector<uint8_t> header(const glm::dvec3& scale, const glm::dvec3& offset) const;
};

void LasRecordWriter::State::encode(const PointRecord* records, size_t n) {
  const bool extended = las::isExtended(f.pointFormat);
  const int rgbOffset = las::kRgbOffset[static_cast<size_t>(f.pointFormat)];
  buffer.assign(n * recordLength, 0);
  for (size_t k = 0; k < n; ++k) {
    const PointRecord& p = records[k];
    uint8_t* r = buffer.data() + k * recordLength;
    storeLE<int32_t>(r, p.x);
    storeLE<int32_t>(r + 4, p.y);
    storeLE<int32_t>(r + 8, p.z);
    storeLE<uint16_t>(r + 12, fields.intensity ? p.intensity : 0);
    // Number of returns is not kept by records; writing it equal to the return number keeps the record
    // valid (return number <= number of returns).
    uint8_t rn = fields.returnNumber ? p.returnNumber : 1;
    const uint8_t cls = fields.classification ? p.classification : 0;
    if (extended) {
      rn &= 0x0F;
      r[14] = static_cast<uint8_t>(rn | (rn << 4)); // return number bits 0-3, number of returns 4-7
      r[16] = cls;
      storeLE<uint16_t>(r + 20, fields.pointSourceId ? p.pointSourceId : 0);
    } else {
      rn &= 0x07;
      r[14] = static_cast<uint8_t>(rn | (rn << 3)); // return number bits 0-2, number of returns 3-5
      r[15] = cls & 0x1F;                           // classes above 31 do not fit formats 0-5
      storeLE<uint16_t>(r + 18, fields.pointSourceId ? p.pointSourceId : 0);
    }
    if (fields.color && rgbOffset >= 0)
      for (int ch = 0; ch < 3; ++ch)
        storeLE<uint16_t>(r + rgbOffset + 2 * ch, p.rgb[ch]);
  }
}

// Public header block, R15 Table 3 (offsets in las_format.h), without the counts and bounds, which
// LasFileWriter fills in from the records.
std::vector<uint8_t> LasRecordWriter::State::header(const glm::dvec3& scale, const glm::dvec3& offset) const {
  const bool extended = las::isExtended(f.pointFormat);
  std::vector<uint8_t> bytes(f.headerSize, 0);
  uint8_t* h = bytes.data();
  std::memcpy(h, "LASF", 4);
  // Global encoding bit 4: CRS (if any) is WKT, required for point formats 6-10 (R15 2.4).
  storeLE<uint16_t>(h + las::kGlobalEncoding, extended ? 0x10 : 0);
  h[las::kVersionMajor] = 1;
  h[las::kVersionMinor] = f.minor;
  las::copyString(h + las::kSystemId, 32, "pointrast");
  las::copyString(h + las::kSoftware, 32, "pointrast");
  std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  storeLE<uint16_t>(h + las::kCreationDay, static_cast<uint16_t>(utc.tm_yday + 1));
  storeLE<uint16_t>(h + las::kCreationYear, static_cast<uint16_t>(utc.tm_year + 1900));
  storeLE<uint16_t>(h + las::kHeaderSizeField, static_cast<uint16_t>(f.headerSize));
  for (int a = 0; a < 3; ++a) {
    storeLE<double>(h + las::kScale + 8 * a, scale[a]);
    storeLE<double>(h + las::kOffset + 8 * a, offset[a]);
  }
  return bytes;
}

LasRecordWriter::LasRecordWriter(const std::filesystem::path& path, const glm::dvec3& scale,
                                 const glm::dvec3& offset, const RecordFields& fields, LasFlavor flavor)
    : state_(std::make_unique<State>(path, flavor)) {
  State& s = *state_;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(scale[a]) || scale[a] == 0.0 || !std::isfinite(offset[a]))
      fail(path, "the cloud's scale/offset cannot be written as LAS");
  s.fields = fields;
  s.recordLength = las::kRecordSize[static_cast<size_t>(s.f.pointFormat)];
  LasFileSetup setup;
  setup.header = s.header(scale, offset);
  setup.pointFormat = s.f.pointFormat;
  setup.recordLength = s.recordLength;
  setup.laz = isLazPath(path);
  s.out.emplace(path, std::move(setup));
}

LasRecordWriter::~LasRecordWriter() = default;

void LasRecordWriter::write(const PointRecord* records, size_t count) {
  State& s = *state_;
  if (s.f.minor < 4 && s.out->pointsWritten() + count > UINT32_MAX)
    fail(s.path, "more than 4294967295 points do not fit in LAS 1.2; write LAS 1.4");
  for (size_t first = 0; first < count; first += kChunkPoints) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(kChunkPoints, count - first));
    s.encode(records + first, n);
    s.out->write(s.buffer.data(), n);
  }
}

uint64_t LasRecordWriter::pointsWritten() const {
  return state_->out->pointsWritten();
}

void LasRecordWriter::commit() {
  state_->out->commit();
}

void writeLas(const std::filesystem::path& path, const PointCloud& cloud, LasFlavor flavor) {
  const FlavorInfo f = flavorInfo(flavor);
  const uint64_t n = cloud.size();
  if (f.minor < 4 && n > UINT32_MAX)
    fail(path, strFormat("%llu points do not fit in LAS 1.2 (at most 4294967295); write LAS 1.4",
                         static_cast<unsigned long long>(n)));
  // Attributes are used only when they match the point count (an empty array means "none").
  RecordFields fields;
  fields.color = cloud.colors.size() == n && n > 0;
  fields.intensity = cloud.intensity.size() == n && n > 0;
  fields.classification = cloud.classification.size() == n && n > 0;
  fields.returnNumber = cloud.returnNumber.size() == n && n > 0;
  fields.pointSourceId = cloud.pointSourceId.size() == n && n > 0;
  LasRecordWriter writer(path, cloud.scale, cloud.offset, fields, flavor);
  std::vector<PointRecord> records(static_cast<size_t>(std::min(n, kChunkPoints)));
  for (uint64_t first = 0; first < n; first += kChunkPoints) {
    const uint64_t count = std::min(kChunkPoints, n - first);
    for (uint64_t k = 0; k < count; ++k) {
      const uint64_t i = first + k;
      PointRecord& r = records[k];
      r.x = cloud.positions[3 * i];
      r.y = cloud.positions[3 * i + 1];
      r.z = cloud.positions[3 * i + 2];
      if (fields.color) {
        // 16-bit channels: v * 257 (= v << 8 | v) maps 0..255 onto the full 0..65535 range.
        const uint32_t c = cloud.colors[i];
        for (int ch = 0; ch < 3; ++ch)
          r.rgb[ch] = static_cast<uint16_t>(((c >> (8 * ch)) & 0xFF) * 257);
      }
      if (fields.intensity) r.intensity = cloud.intensity[i];
      if (fields.classification) r.classification = cloud.classification[i];
      if (fields.returnNumber) r.returnNumber = cloud.returnNumber[i];
      if (fields.pointSourceId) r.pointSourceId = cloud.pointSourceId[i];
    }
    writer.write(records.data(), static_cast<size_t>(count));
  }
  writer.commit();
}

} // namespace pointrast::io

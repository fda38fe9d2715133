// LAZ reader: openLaz() validates the container, decodeLazInWindows() decodes chunks on all cores, and
// the shared LAS record parser maps the raw records into the cloud, exactly as for an uncompressed file.
#include "io/las/laz_reader.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <optional>
#include <thread>

#include "base/parallel.h"
#include "base/progress.h"
#include "io/copc_ept/copc.h"
#include "io/las/las_attributes.h"
#include "io/las/las_records.h"

namespace pointrast::io {

using namespace detail;

namespace {

std::atomic<unsigned> gLazThreads{0};

// Chunks in flight per thread: enough that a slow chunk rarely idles the others at the window's end.
constexpr size_t kChunksPerThread = 2;

unsigned resolveThreads(unsigned threads) {
  return threads ? threads : hardwareThreads();
}

} // namespace

namespace detail {

void setLazThreads(unsigned threads) {
  gLazThreads = threads;
}
unsigned lazThreads() {
  return gLazThreads;
}

void decodeLazInWindows(const InputFile& file, const laz::LazFile& laz, unsigned threads,
                        const ChunkWindowFn& deliver, size_t beginChunk, size_t endChunk) {
  const size_t chunks = std::min(endChunk, laz.chunks.size());
  if (beginChunk >= chunks) return;
  threads = static_cast<unsigned>(std::min<size_t>(resolveThreads(threads), chunks - beginChunk));
  const size_t window = threads * kChunksPerThread;
  std::vector<std::vector<uint8_t>> records(std::min(window, chunks - beginChunk));
  // One decoder per thread for the whole file: its models are allocated once.
  std::vector<std::unique_ptr<laz::ChunkDecoder>> decoders(threads);
  std::vector<std::vector<uint8_t>> scratch(threads);
  for (size_t first = beginChunk; first < chunks; first += window) {
    const size_t last = std::min(chunks, first + window);
    std::atomic<size_t> next{first};
    std::exception_ptr error;
    std::mutex errorMutex;
    auto work = [&](unsigned t) {
      try {
        if (!decoders[t]) decoders[t] = std::make_unique<laz::ChunkDecoder>(laz.layout);
        for (size_t i = next++; i < last; i = next++)
          laz::decodeChunk(file, laz, i, *decoders[t], scratch[t], records[i - first]);
      } catch (...) {
        std::lock_guard lock(errorMutex);
        if (!error) error = std::current_exception();
        next = last;
      }
    };
    const unsigned active = static_cast<unsigned>(std::min<size_t>(threads, last - first));
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < active; ++t)
      pool.emplace_back(work, t);
    work(0);
    for (std::thread& t : pool)
      t.join();
    if (error) std::rethrow_exception(error);
    records.resize(last - first);
    deliver(first, records);
  }
}

struct ChunkDecoderPool::Slot {
  laz::ChunkDecoder decoder;
  std::vector<uint8_t> bytes;
  explicit Slot(const laz::Layout& layout) : decoder(layout) {}
};

ChunkDecoderPool::ChunkDecoderPool(laz::Layout layout) : layout_(std::move(layout)) {}
ChunkDecoderPool::~ChunkDecoderPool() = default;

void ChunkDecoderPool::decode(const InputFile& file, const laz::Chunk& chunk, const std::string& what,
                              std::vector<uint8_t>& records) {
  std::unique_ptr<Slot> slot;
  {
    std::lock_guard lock(mutex_);
    if (!idle_.empty()) {
      slot = std::move(idle_.back());
      idle_.pop_back();
    }
  }
  if (!slot) slot = std::make_unique<Slot>(layout_);
  laz::decodeChunkAt(file, chunk, what, slot->decoder, slot->bytes, records);
  std::lock_guard lock(mutex_);
  idle_.push_back(std::move(slot));
}

} // namespace detail

namespace {

// The arrays of a cloud for points [first, ...), as the record parser fills them.
RecordDestination destinationAt(PointCloud& cloud, uint64_t first, bool keepAttributes) {
  RecordDestination d;
  d.positions = cloud.positions.data() + 3 * first;
  if (!cloud.colors.empty()) d.colors = cloud.colors.data() + first;
  if (keepAttributes) {
    d.intensity = cloud.intensity.data() + first;
    d.classification = cloud.classification.data() + first;
    d.returnNumber = cloud.returnNumber.data() + first;
    d.pointSourceId = cloud.pointSourceId.data() + first;
  }
  return d;
}

void resizeCloud(PointCloud& cloud, uint64_t n, bool color, bool keepAttributes) {
  cloud.positions.resize(3 * n);
  if (color) cloud.colors.resize(n);
  if (keepAttributes) {
    cloud.intensity.resize(n);
    cloud.classification.resize(n);
    cloud.returnNumber.resize(n);
    cloud.pointSourceId.resize(n);
  }
}

uint16_t colorMax(const uint8_t* records, uint64_t count, size_t recordLength, int rgbOffset) {
  uint16_t hi = 0;
  for (uint64_t i = 0; i < count; ++i) {
    const uint8_t* rgb = records + i * recordLength + rgbOffset;
    hi = std::max({hi, loadLE<uint16_t>(rgb), loadLE<uint16_t>(rgb + 2), loadLE<uint16_t>(rgb + 4)});
  }
  return hi;
}

} // namespace

PointCloud readLazRange(const std::filesystem::path& path, const ReadOptions& options, uint64_t firstRecord,
                        uint64_t recordCount, LazColorDepths* depths) {
  InputFile file(path);
  const laz::LazFile laz = laz::openLaz(file);
  const LasHeader& hd = laz.header;
  const size_t recordLength = hd.recordLength;
  const bool extended = las::isExtended(hd.pointFormat);
  const int rgbOffset = hd.rgbOffset();
  const bool keep = options.keepAttributes;

  // The chunks that hold the records asked for (chunk i holds [firstPoint, firstPoint + pointCount));
  // the whole file decodes every chunk and keeps every record decoded.
  const uint64_t filePoints =
      laz.chunks.empty() ? 0 : laz.chunks.back().firstPoint + laz.chunks.back().pointCount;
  const bool whole = firstRecord == 0 && recordCount >= filePoints;
  firstRecord = std::min(firstRecord, filePoints);
  const uint64_t endRecord =
      whole ? UINT64_MAX : firstRecord + std::min(recordCount, filePoints - firstRecord);
  const uint64_t wanted = whole ? filePoints : endRecord - firstRecord;
  size_t beginChunk = 0, endChunk = laz.chunks.size();
  if (!whole && wanted == 0) {
    endChunk = 0;
  } else if (!whole) {
    const auto first = laz.chunks.begin();
    beginChunk = size_t(std::partition_point(
                            first, laz.chunks.end(),
                            [&](const laz::Chunk& c) { return c.firstPoint + c.pointCount <= firstRecord; }) -
                        first);
    endChunk = size_t(std::partition_point(first, laz.chunks.end(),
                                           [&](const laz::Chunk& c) { return c.firstPoint < endRecord; }) -
                      first);
  }

  PointCloud cloud;
  cloud.source = path.filename().string();
  cloud.scale = hd.scale;
  cloud.offset = hd.offset;
  // The header's count is only a claim until the chunks decode; reserving at most one point per file
  // byte keeps a lying count from allocating (real LAZ files hold 3-10 bytes per point).
  const uint64_t reserve = std::min<uint64_t>(wanted, file.size());
  cloud.positions.reserve(3 * reserve);
  if (hd.hasColor()) cloud.colors.reserve(reserve);
  if (keep) {
    cloud.intensity.reserve(reserve);
    cloud.classification.reserve(reserve);
    cloud.returnNumber.reserve(reserve);
  }

  std::optional<Progress> progress;
  if (options.progress) progress.emplace("reading " + path.filename().string(), wanted);
  RecordStats total;
  // Colors: each chunk is converted by its own depth (8-bit unless a value of the whole chunk exceeds 255);
  // if any chunk was 16-bit, the chunks converted as 8-bit hold only values <= 255, which are black in
  // 16-bit terms (the LAS reader's rule, decided for the whole file).
  LazColorDepths local;
  LazColorDepths& d = depths ? *depths : local;
  d = LazColorDepths{};
  std::vector<RecordStats> stats;
  std::vector<uint64_t> starts, skip;
  decodeLazInWindows(
      file, laz, lazThreads(),
      [&](size_t firstChunk, std::vector<std::vector<uint8_t>>& records) {
        const size_t n = records.size();
        starts.assign(n + 1, cloud.size());
        skip.assign(n, 0);
        for (size_t i = 0; i < n; ++i) {
          const uint64_t first = laz.chunks[firstChunk + i].firstPoint;
          const uint64_t count = records[i].size() / recordLength;
          const uint64_t lo = std::clamp(firstRecord, first, first + count);
          const uint64_t hi = std::clamp(endRecord, first, first + count);
          skip[i] = lo - first;
          starts[i + 1] = starts[i] + (hi - lo);
        }
        resizeCloud(cloud, starts[n], hd.hasColor(), keep);
        stats.assign(n, RecordStats{});
        std::vector<int> shifts(n, 0);
        parallelBlocks(n, 1, [&](uint64_t i, uint64_t, uint64_t) {
          const uint8_t* chunk = records[i].data();
          const uint64_t count = starts[i + 1] - starts[i];
          if (rgbOffset >= 0 &&
              colorMax(chunk, records[i].size() / recordLength, recordLength, rgbOffset) > 255)
            shifts[i] = 8;
          const RecordDestination dest = destinationAt(cloud, starts[i], keep);
          const uint8_t* src = chunk + skip[i] * recordLength;
          if (extended)
            parseRecords<true>(src, recordLength, count, rgbOffset, shifts[i], dest, stats[i]);
          else
            parseRecords<false>(src, recordLength, count, rgbOffset, shifts[i], dest, stats[i]);
        });
        for (size_t i = 0; i < n; ++i) {
          if (starts[i + 1] == starts[i]) continue;
          for (int a = 0; a < 3; ++a) {
            total.qmin[a] = std::min(total.qmin[a], stats[i].qmin[a]);
            total.qmax[a] = std::max(total.qmax[a], stats[i].qmax[a]);
          }
          if (shifts[i] == 8)
            d.any16 = true;
          else
            d.eightBit.emplace_back(starts[i], starts[i + 1] - starts[i]);
        }
        if (progress) progress->advance(starts[n] - starts[0]);
      },
      beginChunk, endChunk);
  if (progress) progress->finish();
  if (!depths && d.any16) blackenEightBit(cloud, d);

  if (cloud.size() > 0) {
    cloud.bounds = boundsFromQuantized(total.qmin, total.qmax, cloud.scale, cloud.offset);
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(cloud.bounds.min[a]) || !std::isfinite(cloud.bounds.max[a]))
        fail(path, "coordinates overflow after applying the header's scale and offset");
  }
  return cloud;
}

void blackenEightBit(PointCloud& cloud, const LazColorDepths& depths) {
  if (cloud.colors.empty()) return;
  for (const auto& [first, count] : depths.eightBit)
    std::fill_n(cloud.colors.begin() + static_cast<ptrdiff_t>(first), count, packRgba(0, 0, 0));
}

PointCloud readLaz(const std::filesystem::path& path, const ReadOptions& options) {
  return readLazRange(path, options, 0, UINT64_MAX, nullptr);
}

std::vector<uint8_t> readLazRecords(const std::filesystem::path& path, unsigned threads) {
  InputFile file(path);
  const laz::LazFile laz = laz::openLaz(file);
  std::vector<uint8_t> out;
  decodeLazInWindows(file, laz, threads, [&](size_t, std::vector<std::vector<uint8_t>>& records) {
    for (const std::vector<uint8_t>& r : records)
      out.insert(out.end(), r.begin(), r.end());
  });
  return out;
}

} // namespace pointrast::io

namespace pointrast::io::detail {

namespace {

std::string describeChunks(const laz::LazFile& laz) {
  const size_t n = laz.chunks.size();
  if (!laz.layout.variableChunks()) return strFormat("%zu of %u points", n, laz.layout.chunkSize);
  uint64_t lo = UINT64_MAX, hi = 0;
  for (const laz::Chunk& c : laz.chunks) {
    lo = std::min(lo, c.pointCount);
    hi = std::max(hi, c.pointCount);
  }
  if (n == 0) return "0 (variable size)";
  return strFormat("%zu of variable size (%llu .. %llu points)", n, static_cast<unsigned long long>(lo),
                   static_cast<unsigned long long>(hi));
}

} // namespace

FileInfo probeLaz(const std::filesystem::path& path) {
  InputFile file(path);
  const laz::LazFile laz = laz::openLaz(file);
  const LasHeader& hd = laz.header;
  // The bit depth of colors is a property of the values, as for LAS: every chunk is decoded.
  uint16_t lo = UINT16_MAX, hi = 0;
  if (hd.hasColor()) {
    const int rgbOffset = hd.rgbOffset();
    decodeLazInWindows(file, laz, lazThreads(), [&](size_t, std::vector<std::vector<uint8_t>>& records) {
      for (const std::vector<uint8_t>& r : records)
        for (size_t i = 0; i + hd.recordLength <= r.size(); i += hd.recordLength)
          for (int c = 0; c < 3; ++c) {
            const uint16_t v = loadLE<uint16_t>(r.data() + i + rgbOffset + 2 * c);
            lo = std::min(lo, v);
            hi = std::max(hi, v);
          }
    });
  }
  FileInfo info = describeLasHeader(hd, "LAZ", lo, hi);
  const laz::Layout& layout = laz.layout;
  // After the header lines: how the points are compressed.
  info.extra.emplace_back("compression",
                          strFormat("LASzip %u.%ur%u, %s", layout.versionMajor, layout.versionMinor,
                                    layout.versionRevision, layout.describeCompressor().c_str()));
  info.extra.emplace_back("items", layout.describeItems());
  info.extra.emplace_back("chunks", describeChunks(laz));
  if (const std::optional<CopcSummary> copc = summarizeCopc(path)) {
    info.extra.emplace_back(
        "COPC", strFormat("1.0, root cube center %.6f, %.6f, %.6f, half size %g, spacing %g", copc->center.x,
                          copc->center.y, copc->center.z, copc->halfSize, copc->spacing));
    info.extra.emplace_back("COPC hierarchy",
                            strFormat("%llu nodes, depth %d, %llu points, %llu page%s",
                                      (unsigned long long)copc->nodes, copc->depth,
                                      (unsigned long long)copc->points, (unsigned long long)copc->pages,
                                      copc->pages == 1 ? "" : "s"));
    if (!copc->colors.empty()) info.extra.emplace_back("COPC colors", copc->colors);
  }
  return info;
}

} // namespace pointrast::io::detail

namespace pointrast::io {

namespace {

class LazPointSource : public PointSource {
public:
  explicit LazPointSource(const std::filesystem::path& path)
      : file_(path), laz_(laz::openLaz(file_)), pool_(laz_.layout) {
    const LasHeader& hd = laz_.header;
    info_.source = path.filename().string();
    info_.pointCount = hd.pointCount;
    info_.bounds = hd.bounds;
    info_.scale = hd.scale;
    info_.offset = hd.offset;
    info_.fields = lasRecordFields(hd.hasColor());
    for (const laz::Chunk& c : laz_.chunks)
      pieces_.push_back({c.firstPoint, c.pointCount});
    tail_ = lasTailFormat(file_, hd);
  }

  const PointSourceInfo& info() const override { return info_; }
  const std::vector<PointPiece>& pieces() const override { return pieces_; }
  uint64_t pieceBytes(size_t i) const override { return laz_.chunks[i].bytes; }

  void readPiece(size_t i, std::vector<PointRecord>& out) const override {
    std::vector<uint8_t> records;
    decodePiece(i, out, records);
  }

  TailFormat tailFormat() const override { return tail_; }

  void readPieceTails(size_t i, std::vector<PointRecord>& out, const TailFormat& layout,
                      std::vector<uint8_t>& tails) const override {
    const LasHeader& hd = laz_.header;
    std::vector<uint8_t> records;
    decodePiece(i, out, records);
    tails.resize(out.size() * layout.bytes());
    packLasTails(records.data(), hd.recordLength, out.size(), hd.pointFormat, tail_.attributes.extraBytes,
                 layout, tails.data());
  }

private:
  // Chunk i's raw records into `records` and its points into `out`.
  void decodePiece(size_t i, std::vector<PointRecord>& out, std::vector<uint8_t>& records) const {
    const LasHeader& hd = laz_.header;
    pool_.decode(file_, laz_.chunks[i], strFormat("LAZ chunk %zu of %zu", i + 1, laz_.chunks.size()),
                 records);
    const bool extended = las::isExtended(hd.pointFormat);
    const int rgbOffset = hd.rgbOffset();
    out.resize(laz_.chunks[i].pointCount);
    for (size_t k = 0; k < out.size(); ++k)
      out[k] = toPointRecord(records.data() + k * hd.recordLength, extended, rgbOffset);
  }

  InputFile file_;
  laz::LazFile laz_;
  mutable ChunkDecoderPool pool_;
  PointSourceInfo info_;
  std::vector<PointPiece> pieces_;
  TailFormat tail_;
};

} // namespace

std::unique_ptr<PointSource> openLazSource(const std::filesystem::path& path) {
  return std::make_unique<LazPointSource>(path);
}

} // namespace pointrast::io

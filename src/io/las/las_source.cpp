// LAS files as a PointSource: pieces of ~1 M records, each read with positional reads (pread), so any
// number of threads read pieces at once without sharing a file position.
#include "io/las/las_source.h"

#include <algorithm>
#include <atomic>

#include "io/las/las_attributes.h"
#include "io/las/las_format.h"

namespace pointrast::io::detail {

namespace {

// Bytes of records read per positional read within a piece: small enough to stay in a core's L2 cache
// between the read and the decode, large enough that the system call costs nothing.
constexpr uint64_t kReadBytes = uint64_t(1) << 20;

std::atomic<uint64_t> gPieceRecords{kLasPieceRecords};

// Record layout, R15 section 2.6: X, Y, Z int32 at 0, 4, 8; intensity uint16 at 12; byte 14 holds the
// return number in bits 0-2 (formats 0-5) or bits 0-3 (formats 6-10); the classification is bits 0-4
// of byte 15 (formats 0-5) or all of byte 16 (formats 6-10); the point source id is a uint16 at 18
// (formats 0-5, after scan angle rank and user data) or at 20 (6-10, after user data and a 16-bit scan
// angle).
template <bool kExtended>
void decode(const uint8_t* src, uint64_t stride, uint64_t count, int rgbOffset, PointRecord* out) {
  for (uint64_t i = 0; i < count; ++i, src += stride) {
    PointRecord& r = out[i];
    r.x = loadLE<int32_t>(src);
    r.y = loadLE<int32_t>(src + 4);
    r.z = loadLE<int32_t>(src + 8);
    r.intensity = loadLE<uint16_t>(src + 12);
    if constexpr (kExtended) {
      r.returnNumber = src[14] & 0x0F;
      r.classification = src[16];
      r.pointSourceId = loadLE<uint16_t>(src + 20);
    } else {
      r.returnNumber = src[14] & 0x07;
      r.classification = src[15] & 0x1F;
      r.pointSourceId = loadLE<uint16_t>(src + 18);
    }
    if (rgbOffset >= 0) {
      r.rgb[0] = loadLE<uint16_t>(src + rgbOffset);
      r.rgb[1] = loadLE<uint16_t>(src + rgbOffset + 2);
      r.rgb[2] = loadLE<uint16_t>(src + rgbOffset + 4);
    } else {
      r.rgb[0] = r.rgb[1] = r.rgb[2] = 0;
    }
  }
}

class LasSource final : public PointSource {
public:
  explicit LasSource(const std::filesystem::path& path) : file_(path), header_(readLasHeader(file_)) {
    info_.source = path.filename().string();
    info_.pointCount = header_.pointCount;
    info_.bounds = header_.bounds;
    info_.scale = header_.scale;
    info_.offset = header_.offset;
    info_.fields.color = header_.hasColor();
    info_.fields.intensity = true;
    info_.fields.returnNumber = true;
    info_.fields.classification = true;
    info_.fields.pointSourceId = true;
    info_.fields.colorMax = 0; // a property of the values, known only after reading them all
    const uint64_t per = pieceRecords();
    for (uint64_t first = 0; first < header_.pointCount; first += per)
      pieces_.push_back({first, std::min(per, header_.pointCount - first)});
    tail_ = lasTailFormat(file_, header_);
  }

  const PointSourceInfo& info() const override { return info_; }
  const std::vector<PointPiece>& pieces() const override { return pieces_; }

  void readPiece(size_t i, std::vector<PointRecord>& out) const override {
    const PointPiece& piece = pieces_.at(i);
    const uint64_t stride = header_.recordLength;
    out.resize(piece.count);
    // readLasHeader checked pointCount * recordLength against the file size, so every read is inside it.
    thread_local std::vector<uint8_t> buffer;
    const uint64_t perRead = std::max<uint64_t>(1, kReadBytes / stride);
    buffer.resize(static_cast<size_t>(std::min(perRead, piece.count) * stride));
    for (uint64_t done = 0; done < piece.count; done += perRead) {
      const uint64_t n = std::min(perRead, piece.count - done);
      file_.readAt(header_.pointOffset + (piece.first + done) * stride, buffer.data(), n * stride);
      decodeLasRecords(buffer.data(), stride, n, header_.pointFormat, out.data() + done);
    }
  }

  uint64_t pieceBytes(size_t i) const override { return pieces_.at(i).count * header_.recordLength; }

  TailFormat tailFormat() const override { return tail_; }

  void readPieceTails(size_t i, std::vector<PointRecord>& out, const TailFormat& layout,
                      std::vector<uint8_t>& tails) const override {
    const PointPiece& piece = pieces_.at(i);
    const uint64_t stride = header_.recordLength;
    out.resize(piece.count);
    tails.resize(piece.count * layout.bytes());
    thread_local std::vector<uint8_t> buffer;
    const uint64_t perRead = std::max<uint64_t>(1, kReadBytes / stride);
    buffer.resize(static_cast<size_t>(std::min(perRead, piece.count) * stride));
    for (uint64_t done = 0; done < piece.count; done += perRead) {
      const uint64_t n = std::min(perRead, piece.count - done);
      file_.readAt(header_.pointOffset + (piece.first + done) * stride, buffer.data(), n * stride);
      decodeLasRecords(buffer.data(), stride, n, header_.pointFormat, out.data() + done);
      packLasTails(buffer.data(), stride, n, header_.pointFormat, tail_.attributes.extraBytes, layout,
                   tails.data() + done * layout.bytes());
    }
  }

private:
  InputFile file_;
  LasHeader header_;
  PointSourceInfo info_;
  std::vector<PointPiece> pieces_;
  TailFormat tail_;
};

} // namespace

void setPieceRecords(uint64_t records) {
  gPieceRecords = records ? records : kLasPieceRecords;
}
uint64_t pieceRecords() {
  return gPieceRecords;
}

void decodeLasRecords(const uint8_t* src, uint64_t stride, uint64_t count, int pointFormat,
                      PointRecord* out) {
  const int rgbOffset = las::kRgbOffset[static_cast<size_t>(pointFormat)];
  if (las::isExtended(pointFormat))
    decode<true>(src, stride, count, rgbOffset, out);
  else
    decode<false>(src, stride, count, rgbOffset, out);
}

std::unique_ptr<PointSource> openLasSource(const std::filesystem::path& path) {
  return std::make_unique<LasSource>(path);
}

} // namespace pointrast::io::detail

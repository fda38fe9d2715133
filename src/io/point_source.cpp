// openPointSource(): one streaming interface over every point format, through the format table's rows.
// Formats with a streaming source (openPoints: LAS, read piece by piece with positional reads) use it.
// The others that read as a whole cloud (PLY and XYZ/CSV have no random access to records: text lines,
// variable-size PLY lists; a Potree octree) are read once, whole, through their reader and served from
// memory, cut into pieces of the same size as LAS pieces so that callers parallelize alike; such a source
// holds the file's cloud (12-20 B a point) for its lifetime.
#include "io/point_source.h"

#include <algorithm>

#include "io/format_table.h"
#include "io/io_util.h"
#include "io/las/las_format.h"
#include "io/las/las_source.h"
#include "io/reader.h"

namespace pointrast::io {

using namespace detail;

namespace {

class CloudSource final : public PointSource {
public:
  explicit CloudSource(PointCloud cloud) : cloud_(std::move(cloud)) {
    info_.source = cloud_.source;
    info_.pointCount = cloud_.size();
    info_.bounds = cloud_.bounds;
    info_.scale = cloud_.scale;
    info_.offset = cloud_.offset;
    info_.fields.color = cloud_.hasColor();
    info_.fields.intensity = !cloud_.intensity.empty();
    info_.fields.returnNumber = !cloud_.returnNumber.empty();
    info_.fields.classification = !cloud_.classification.empty();
    // The readers keep 8-bit colors (packRgba), whatever the file stored.
    info_.fields.colorMax = cloud_.hasColor() ? 255 : 0;
    const uint64_t per = pieceRecords();
    for (uint64_t first = 0; first < info_.pointCount; first += per)
      pieces_.push_back({first, std::min(per, info_.pointCount - first)});
  }

  const PointSourceInfo& info() const override { return info_; }
  const std::vector<PointPiece>& pieces() const override { return pieces_; }

  void readPiece(size_t i, std::vector<PointRecord>& out) const override {
    const PointPiece& piece = pieces_.at(i);
    out.assign(piece.count, PointRecord{});
    for (uint64_t k = 0; k < piece.count; ++k) {
      const uint64_t j = piece.first + k;
      PointRecord& r = out[k];
      r.x = cloud_.positions[3 * j];
      r.y = cloud_.positions[3 * j + 1];
      r.z = cloud_.positions[3 * j + 2];
      if (info_.fields.color) {
        const uint32_t c = cloud_.colors[j];
        r.rgb[0] = c & 0xFF;
        r.rgb[1] = (c >> 8) & 0xFF;
        r.rgb[2] = (c >> 16) & 0xFF;
      }
      if (info_.fields.intensity) r.intensity = cloud_.intensity[j];
      if (info_.fields.returnNumber) r.returnNumber = cloud_.returnNumber[j];
      if (info_.fields.classification) r.classification = cloud_.classification[j];
    }
  }

  uint64_t pieceBytes(size_t) const override { return 0; }

private:
  PointCloud cloud_;
  PointSourceInfo info_;
  std::vector<PointPiece> pieces_;
};

} // namespace

std::unique_ptr<PointSource> openPointSource(const std::filesystem::path& path) {
  const FormatInfo* format = detectFormat(path);
  if (format && format->openPoints) return format->openPoints(path);
  if (format && format->read) {
    ReadOptions options;
    options.progress = true;
    return std::make_unique<CloudSource>(format->read(path, options));
  }
  // readCloud gives the one sentence for every other input (compressed, particles, empty, unknown).
  readCloud(path);
  fail(path, "not a point cloud this build can stream");
}

} // namespace pointrast::io

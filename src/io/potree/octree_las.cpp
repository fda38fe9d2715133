// Octree -> LAS or LAZ export (writer.h): every node's records straight into LasRecordWriter, nodes
// decoded on all cores a batch at a time and written in forEachNode order. An octree whose points carry
// the tails of LAS records (cloud/lod_tails.h) is written in the point format they came from, with its
// extra bytes and their descriptors: the records as they were.
#include <algorithm>
#include <ctime>
#include <optional>

#include "base/parallel.h"
#include "base/progress.h"
#include "cloud/lod_tails.h"
#include "io/io_util.h"
#include "io/las/las_attributes.h"
#include "io/las/las_format.h"
#include "io/writer.h"

namespace pointrast::io {

using namespace detail;

namespace {

// Points decoded per batch (~100 MB of records): enough nodes to keep every core busy.
constexpr uint64_t kBatchPoints = uint64_t(4) << 20;

// The point as a filter sees it: a record holds no number of returns and no GPS time (the caller has
// refused filters on them).
FilterPoint filterPoint(const PointRecord& r, const lod::OctreeMetadata& meta) {
  FilterPoint p;
  p.position = glm::dvec3(r.x, r.y, r.z) * meta.scale + meta.offset;
  p.classification = r.classification;
  p.returnNumber = r.returnNumber;
  p.intensity = r.intensity;
  p.pointSourceId = r.pointSourceId;
  return p;
}

// Records with tails as LAS records of the tail's point format (waveform formats without their packets,
// which are not carried), through LasFileWriter.
class TailRecordWriter {
public:
  TailRecordWriter(const std::filesystem::path& path, const lod::OctreeMetadata& meta, const TailFormat& tail)
      : tail_(tail), format_(las::withoutWaveform(tail.lasPointFormat)) {
    const bool extended = las::isExtended(format_);
    recordLength_ = static_cast<uint16_t>(las::kRecordSize[size_t(format_)] + tail.attributes.extraBytes);
    LasFileSetup setup;
    setup.header.assign(extended ? las::kHeaderSize14 : las::kHeaderSize12, 0);
    uint8_t* h = setup.header.data();
    std::memcpy(h, "LASF", 4);
    storeLE<uint16_t>(h + las::kGlobalEncoding, extended ? 0x10 : 0); // WKT, required for formats 6-10
    h[las::kVersionMajor] = 1;
    h[las::kVersionMinor] = extended ? 4 : 2;
    las::copyString(h + las::kSystemId, 32, "pointrast");
    las::copyString(h + las::kSoftware, 32, "pointrast");
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    storeLE<uint16_t>(h + las::kCreationDay, static_cast<uint16_t>(utc.tm_yday + 1));
    storeLE<uint16_t>(h + las::kCreationYear, static_cast<uint16_t>(utc.tm_year + 1900));
    storeLE<uint16_t>(h + las::kHeaderSizeField, static_cast<uint16_t>(setup.header.size()));
    for (int a = 0; a < 3; ++a) {
      storeLE<double>(h + las::kScale + 8 * a, meta.scale[a]);
      storeLE<double>(h + las::kOffset + 8 * a, meta.offset[a]);
    }
    if (tail.attributes.extraBytes > 0 && !tail.extraBytesDescriptors.empty() &&
        tail.extraBytesDescriptors.size() <= UINT16_MAX)
      setup.vlrs.push_back(las::vlrBytes("LASF_Spec", 4, "Extra bytes", tail.extraBytesDescriptors));
    setup.pointFormat = format_;
    setup.recordLength = recordLength_;
    setup.laz = isLazPath(path);
    out_.emplace(path, std::move(setup));
  }

  void write(const PointRecord* records, const uint8_t* tails, size_t count) {
    const bool extended = las::isExtended(format_);
    const int rgbOffset = las::kRgbOffset[size_t(format_)];
    const uint32_t tailBytes = tail_.bytes();
    buffer_.assign(count * recordLength_, 0);
    for (size_t k = 0; k < count; ++k) {
      const PointRecord& p = records[k];
      uint8_t* r = buffer_.data() + k * recordLength_;
      storeLE<int32_t>(r, p.x);
      storeLE<int32_t>(r + 4, p.y);
      storeLE<int32_t>(r + 8, p.z);
      storeLE<uint16_t>(r + 12, p.intensity);
      // The number of returns equal to the return number, where the tail holds none (pruneTail).
      if (extended) {
        r[14] = static_cast<uint8_t>((p.returnNumber & 0x0F) * 0x11);
        r[16] = p.classification;
        storeLE<uint16_t>(r + 20, p.pointSourceId);
      } else {
        r[14] = static_cast<uint8_t>((p.returnNumber & 0x07) * 9);
        r[15] = p.classification & 0x1F;
        storeLE<uint16_t>(r + 18, p.pointSourceId);
      }
      if (rgbOffset >= 0)
        for (int c = 0; c < 3; ++c)
          storeLE<uint16_t>(r + rgbOffset + 2 * c, p.rgb[c]);
      if (tailBytes > 0)
        detail::unpackLasAttributes(tails + k * tailBytes, tail_.layout, tail_.attributes, format_, r);
    }
    out_->write(buffer_.data(), count);
  }
  uint64_t pointsWritten() const { return out_->pointsWritten(); }
  void commit() { out_->commit(); }

private:
  const TailFormat& tail_;
  int format_;
  uint16_t recordLength_ = 0;
  std::optional<LasFileWriter> out_;
  std::vector<uint8_t> buffer_;
};

} // namespace

uint64_t writeLasFromOctree(const std::filesystem::path& path, lod::NodeSource& source, LasFlavor flavor,
                            bool progress, const PointFilter* filter, ClipNodeStats* nodeStats) {
  const lod::OctreeMetadata& meta = source.metadata();
  if (filter && !filter->active()) filter = nullptr;
  PointFilter attributesOnly; // for nodes the clip keeps as a whole
  if (filter) {
    attributesOnly = *filter;
    attributesOnly.boxes.clear();
    attributesOnly.orientedBoxes.clear();
    attributesOnly.polygons.clear();
  }
  // A node's points lie in its cube, up to rounding onto its faces: two quantization steps of margin.
  const double grow = 2 * std::max({meta.scale.x, meta.scale.y, meta.scale.z});
  std::vector<lod::NodeInfo> nodes;
  std::vector<BoxVerdict> verdicts;
  uint64_t listed = 0;
  lod::forEachNode(source, [&](const lod::NodeInfo& node) {
    BoxVerdict v = BoxVerdict::Some;
    if (filter && filter->hasClip()) {
      Bounds cube = meta.nodeCube(node.key);
      cube.min -= grow;
      cube.max += grow;
      v = clipVerdict(*filter, cube);
      if (nodeStats) {
        ++nodeStats->nodes;
        nodeStats->skipped += v == BoxVerdict::None;
      }
      if (v == BoxVerdict::None) return true;
    }
    nodes.push_back(node);
    verdicts.push_back(v);
    listed += node.pointCount;
    return true;
  });
  auto* tailed = dynamic_cast<lod::NodeTails*>(&source);
  if (tailed && tailed->tailFormat().lasPointFormat < 0) tailed = nullptr;
  std::optional<LasRecordWriter> writer;
  std::optional<TailRecordWriter> tailWriter;
  if (tailed)
    tailWriter.emplace(path, meta, tailed->tailFormat());
  else
    writer.emplace(path, meta.scale, meta.offset, meta.fields, flavor);
  const uint32_t tailBytes = tailed ? tailed->tailFormat().bytes() : 0;
  std::optional<Progress> line;
  if (progress) line.emplace("exporting " + meta.source, listed);
  for (size_t begin = 0; begin < nodes.size();) {
    size_t end = begin;
    uint64_t points = 0;
    while (end < nodes.size() && (end == begin || points + nodes[end].pointCount <= kBatchPoints))
      points += nodes[end++].pointCount;
    std::vector<std::vector<PointRecord>> batch(end - begin);
    std::vector<std::vector<uint8_t>> tails(end - begin);
    parallelBlocks(end - begin, 1, [&](uint64_t k, uint64_t, uint64_t) {
      if (tailed)
        batch[k] = tailed->readNodeTails(nodes[begin + k], tails[k]);
      else
        batch[k] = source.readNode(nodes[begin + k]);
      if (line) line->advance(batch[k].size());
      if (filter) {
        const PointFilter& test = verdicts[begin + k] == BoxVerdict::All ? attributesOnly : *filter;
        size_t kept = 0;
        for (size_t i = 0; i < batch[k].size(); ++i) {
          if (!passes(test, filterPoint(batch[k][i], meta))) continue;
          batch[k][kept] = batch[k][i];
          if (tailed && tailBytes)
            std::memmove(&tails[k][kept * tailBytes], &tails[k][i * tailBytes], tailBytes);
          ++kept;
        }
        batch[k].resize(kept);
      }
    });
    for (size_t k = 0; k < batch.size(); ++k)
      if (tailed)
        tailWriter->write(batch[k].data(), tails[k].data(), batch[k].size());
      else
        writer->write(batch[k].data(), batch[k].size());
    begin = end;
  }
  if (line) line->finish();
  const uint64_t written = tailed ? tailWriter->pointsWritten() : writer->pointsWritten();
  if (tailed)
    tailWriter->commit();
  else
    writer->commit();
  return written;
}

} // namespace pointrast::io

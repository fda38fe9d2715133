// How a node's points become the node cache's page layout (shared.h, "Level of detail"): positions quantized
// to 30 bits per axis in the node's tight bounds and split into three words as a batch's are
// (cloud/batch_words.h), colors as the brute-force methods display them (cloud/cloud.h, displayColors), with
// one color mode for the whole octree so that neighbouring nodes agree.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cloud/cloud.h"
#include "cloud/octree.h"

namespace pointrast::lod {

class NodeEncoder {
public:
  // Decides the display colors from a sample of the octree (its root's points, a subsample of the whole):
  // RGB where the source has a usable one (16-bit when its values pass 255), else a ramp over intensity or
  // elevation with the sample's percentiles.
  NodeEncoder(const OctreeMetadata& metadata, const std::vector<PointRecord>& sample);

  // Encodes one node's records into pages: pages[k] receives points [k * 4096, (k + 1) * 4096) in the four
  // sections of a page (kLodPageBytes each, pagesOf(records.size()) of them). Returns the tight world bounds
  // the points were quantized in. Thread-safe.
  Bounds encode(const std::vector<PointRecord>& records, std::span<uint8_t* const> pages) const;

private:
  PointCloud cloudOf(const std::vector<PointRecord>& records) const;
  OctreeMetadata metadata_;
  int colorShift_ = 0;
  DisplayColorMode mode_;
};

} // namespace pointrast::lod

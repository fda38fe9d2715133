// The octree builder's COPC output next to its Potree output of the same build: both built from one input,
// read back through their readers as maps from node key to the node's points (sorted: a multiset).
#pragma once

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "io/copc_ept/copc.h"
#include "io/copc_ept/copc_writer.h"
#include "io/potree/lod_potree.h"

namespace copctest {

using pointrast::PointRecord;
using pointrast::lod::NodeKey;
using Nodes = std::map<NodeKey, std::vector<PointRecord>>;

inline bool recordLess(const PointRecord& a, const PointRecord& b) {
  return std::memcmp(&a, &b, sizeof a) < 0;
}

// Every node with points, as the source serves it; fields the source does not carry are zeroed, and each
// node's count is checked against what its hierarchy says.
inline Nodes readNodes(pointrast::lod::NodeSource& source) {
  const pointrast::RecordFields& f = source.metadata().fields;
  Nodes nodes;
  pointrast::lod::forEachNode(source, [&](const pointrast::lod::NodeInfo& info) {
    std::vector<PointRecord> records = source.readNode(info);
    EXPECT_EQ(records.size(), info.pointCount) << info.key.potreeName();
    if (records.empty()) return true;
    for (PointRecord& r : records) {
      if (!f.color) r.rgb[0] = r.rgb[1] = r.rgb[2] = 0;
      if (!f.intensity) r.intensity = 0;
      if (!f.returnNumber) r.returnNumber = 0;
      if (!f.classification) r.classification = 0;
      if (!f.pointSourceId) r.pointSourceId = 0;
    }
    std::sort(records.begin(), records.end(), recordLess);
    EXPECT_TRUE(nodes.emplace(info.key, std::move(records)).second) << info.key.potreeName();
    return true;
  });
  return nodes;
}

struct Builds {
  std::filesystem::path potree, copc;
  pointrast::io::CopcBuildReport copcReport;
};

// Builds `inputs` into dir/potree and dir/octree.copc.laz with the same options.
inline Builds buildBoth(const std::vector<std::filesystem::path>& inputs, const std::filesystem::path& dir,
                        pointrast::io::LodBuildOptions options, pointrast::io::CopcWriteOptions copc = {}) {
  options.progress = false;
  std::filesystem::create_directories(dir);
  Builds b{dir / "potree", dir / "octree.copc.laz", {}};
  pointrast::io::PotreeWriteOptions potree;
  potree.name = "octree";
  pointrast::io::buildPotree(inputs, b.potree, options, potree);
  b.copcReport = pointrast::io::buildCopc(inputs, b.copc, options, copc);
  return b;
}

} // namespace copctest

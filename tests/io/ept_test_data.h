// Small EPT datasets for tests, made from real data: the octree of shared/data/laz/lone-star.copc.laz
// (15 nodes) written as EPT with binary, zstandard or laszip node data. No EPT dataset is in
// shared/data; COPC and EPT describe the same octree (root cube, voxel keys, span = cube / spacing),
// and a COPC node's chunk composed into its own LAZ file is exactly an EPT laszip node.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <zstd.h>

#include "io/copc_ept/copc.h"
#include "io/io_test_util.h"
#include "io/las/laz_compose.h"
#include "io/las/laz_format.h"

namespace iotest {

struct EptNode {
  pointrast::lod::NodeKey key;
  std::vector<pointrast::PointRecord> records;
  size_t chunk = 0; // the COPC chunk holding the node (for laszip data)
};

inline std::string eptKey(const pointrast::lod::NodeKey& k) {
  return std::to_string(k.level) + "-" + std::to_string(k.x) + "-" + std::to_string(k.y) + "-" +
         std::to_string(k.z);
}

// The COPC file's nodes with their records and chunk indices.
inline std::vector<EptNode> copcNodes(const std::filesystem::path& copc) {
  auto source = pointrast::io::openCopc(copc);
  pointrast::io::detail::InputFile file(copc);
  const auto laz = pointrast::io::laz::openLaz(file);
  std::vector<EptNode> nodes;
  pointrast::lod::forEachNode(*source, [&](const pointrast::lod::NodeInfo& n) {
    EptNode node{n.key, source->readNode(n), 0};
    for (size_t c = 0; c < laz.chunks.size(); ++c)
      if (laz.chunks[c].pointCount == n.pointCount && laz.chunks[c].bytes == source->nodeBytes(n))
        node.chunk = c;
    nodes.push_back(std::move(node));
    return true;
  });
  return nodes;
}

// Binary EPT points of the schema written by writeEpt: X, Y, Z int32, Intensity u16, ReturnNumber u8,
// Classification u8, PointSourceId u16, GpsTime double (always 0: PointRecord has none), 26 bytes.
inline std::vector<uint8_t> eptBinary(const std::vector<pointrast::PointRecord>& records) {
  std::vector<uint8_t> out;
  auto put = [&](const void* p, size_t n) {
    out.insert(out.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
  };
  for (const pointrast::PointRecord& r : records) {
    put(&r.x, 4);
    put(&r.y, 4);
    put(&r.z, 4);
    put(&r.intensity, 2);
    put(&r.returnNumber, 1);
    put(&r.classification, 1);
    put(&r.pointSourceId, 2);
    const double gps = 0;
    put(&gps, 8);
  }
  return out;
}

// Writes the dataset into dir. splitAt: a level-1 node whose subtree goes into its own hierarchy file
// (a -1 in the root file), or none. Returns the path of ept.json.
inline std::filesystem::path writeEpt(const std::filesystem::path& copc, const std::filesystem::path& dir,
                                      const std::string& dataType, bool split = true) {
  namespace fs = std::filesystem;
  auto source = pointrast::io::openCopc(copc);
  const auto& m = source->metadata();
  const std::vector<EptNode> nodes = copcNodes(copc);
  fs::create_directories(dir / "ept-data");
  fs::create_directories(dir / "ept-hierarchy");
  nlohmann::json schema = nlohmann::json::array();
  const char* axes[3] = {"X", "Y", "Z"};
  for (int a = 0; a < 3; ++a)
    schema.push_back(
        {{"name", axes[a]}, {"type", "signed"}, {"size", 4}, {"scale", m.scale[a]}, {"offset", m.offset[a]}});
  schema.push_back({{"name", "Intensity"}, {"type", "unsigned"}, {"size", 2}});
  schema.push_back({{"name", "ReturnNumber"}, {"type", "unsigned"}, {"size", 1}});
  schema.push_back({{"name", "Classification"}, {"type", "unsigned"}, {"size", 1}});
  schema.push_back({{"name", "PointSourceId"}, {"type", "unsigned"}, {"size", 2}});
  schema.push_back({{"name", "GpsTime"}, {"type", "float"}, {"size", 8}});
  const double edge = m.cube.max.x - m.cube.min.x;
  nlohmann::json ept = {
      {"bounds", {m.cube.min.x, m.cube.min.y, m.cube.min.z, m.cube.max.x, m.cube.max.y, m.cube.max.z}},
      {"boundsConforming",
       {m.bounds.min.x, m.bounds.min.y, m.bounds.min.z, m.bounds.max.x, m.bounds.max.y, m.bounds.max.z}},
      {"dataType", dataType},
      {"hierarchyType", "json"},
      {"points", m.pointCount},
      {"schema", schema},
      {"span", int(std::lround(edge / m.spacing))},
      {"srs", nlohmann::json::object()},
      {"version", "1.0.0"}};
  writeText(dir / "ept.json", ept.dump(2));

  // Hierarchy: the first level-1 node with children gets its own file when splitting.
  pointrast::lod::NodeKey splitKey{-1, 0, 0, 0};
  for (const EptNode& n : nodes)
    if (split && n.key.level == 2) {
      splitKey = n.key.parent();
      break;
    }
  auto under = [&](const pointrast::lod::NodeKey& k) {
    if (splitKey.level < 0 || k.level < splitKey.level) return false;
    const int up = k.level - splitKey.level;
    return (k.x >> up) == splitKey.x && (k.y >> up) == splitKey.y && (k.z >> up) == splitKey.z;
  };
  nlohmann::json rootFile = nlohmann::json::object(), subFile = nlohmann::json::object();
  for (const EptNode& n : nodes) {
    (under(n.key) ? subFile : rootFile)[eptKey(n.key)] = n.records.size();
  }
  if (splitKey.level >= 0) {
    rootFile[eptKey(splitKey)] = -1;
    writeText(dir / "ept-hierarchy" / (eptKey(splitKey) + ".json"), subFile.dump());
  }
  writeText(dir / "ept-hierarchy" / "0-0-0-0.json", rootFile.dump());

  for (const EptNode& n : nodes) {
    const fs::path base = dir / "ept-data" / eptKey(n.key);
    if (dataType == "binary") {
      writeBytes(base.string() + ".bin", eptBinary(n.records));
    } else if (dataType == "zstandard") {
      const std::vector<uint8_t> raw = eptBinary(n.records);
      std::vector<uint8_t> packed(ZSTD_compressBound(raw.size()));
      packed.resize(ZSTD_compress(packed.data(), packed.size(), raw.data(), raw.size(), 3));
      writeBytes(base.string() + ".zst", packed);
    } else {
      writeBytes(base.string() + ".laz", pointrast::io::composeLaz(copc, {n.chunk}));
    }
  }
  return dir / "ept.json";
}

} // namespace iotest

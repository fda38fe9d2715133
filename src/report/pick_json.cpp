#include "report/pick_json.h"

#include <algorithm>

#include "base/error.h"
#include "cloud/octree.h"
#include "cloud/point_record.h"
#include "render/lod/hierarchy.h"
#include "render/lod/lod_scene.h"

namespace pointrast {

nlohmann::json pickJson(const PointCloud& cloud, uint32_t x, uint32_t y, bool empty,
                        std::optional<uint64_t> index) {
  nlohmann::json j;
  j["pixel"] = {x, y};
  if (empty) {
    j["point"] = "none";
    return j;
  }
  if (!index) {
    j["point"] = "unknown"; // a point was drawn there, but none of the cloud matches its word
    return j;
  }
  const uint64_t i = *index;
  nlohmann::json p;
  p["index"] = i;
  const glm::dvec3 w = cloud.world(i);
  p["x"] = w.x;
  p["y"] = w.y;
  p["z"] = w.z;
  if (!cloud.intensity.empty()) p["intensity"] = cloud.intensity[i];
  if (!cloud.classification.empty()) p["classification"] = cloud.classification[i];
  if (!cloud.returnNumber.empty()) p["return_number"] = cloud.returnNumber[i];
  if (!cloud.pointSourceId.empty()) p["point_source_id"] = cloud.pointSourceId[i];
  if (cloud.hasColor()) {
    const uint32_t c = cloud.colors[i];
    p["color"] = {c & 0xFF, (c >> 8) & 0xFF, (c >> 16) & 0xFF};
  }
  j["point"] = p;
  return j;
}

nlohmann::json pickJson(Renderer& renderer, lod::LodScene& scene, uint32_t x, uint32_t y) {
  std::optional<Renderer::LodPixel> at;
  try {
    at = renderer.lodPointAt(x, y);
  } catch (const InputError& e) {
    return {{"pixel", {x, y}}, {"point", std::string("unavailable: ") + e.what()}};
  }
  if (!at) return pickJson(PointCloud(), x, y, true, std::nullopt);
  const lod::NodeInfo& node = scene.hierarchy().node(at->node).info;
  const std::vector<PointRecord> records = scene.source().readNode(node);
  if (at->index >= records.size()) return pickJson(PointCloud(), x, y, false, std::nullopt);
  // The node's records as a cloud of their own, colors at 8 bits as the node cache shows them.
  const lod::OctreeMetadata& octree = scene.metadata();
  PointCloud cloud;
  cloud.scale = octree.scale;
  cloud.offset = octree.offset;
  uint16_t colorMax = octree.fields.colorMax;
  if (colorMax == 0 && octree.fields.color)
    for (const PointRecord& r : records)
      colorMax = std::max({colorMax, r.rgb[0], r.rgb[1], r.rgb[2]});
  appendRecords(cloud, records.data(), records.size(), octree.fields, colorMax > 255 ? 8 : 0);
  nlohmann::json j = pickJson(cloud, x, y, false, at->index);
  j["point"]["node"] = node.key.potreeName();
  return j;
}

} // namespace pointrast

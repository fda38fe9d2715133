#include "report/pick_json.h"

#include <algorithm>

#include "base/error.h"
#include "cloud/lod_tails.h"
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

namespace {

nlohmann::json number(const lod::TailValue::Number& n) {
  return std::visit([](auto v) { return nlohmann::json(v); }, n);
}

// The tail's attributes beside the record's: LAS fields under their keys, extra bytes fields by name in
// "extra_bytes" (a number, or a list for an array field).
void addTailValues(nlohmann::json& point, const std::vector<lod::TailValue>& values) {
  for (const lod::TailValue& v : values) {
    if (v.values.empty()) continue;
    nlohmann::json value = number(v.values[0]);
    if (v.values.size() > 1) {
      value = nlohmann::json::array();
      for (const lod::TailValue::Number& n : v.values)
        value.push_back(number(n));
    }
    if (v.extraBytes)
      point["extra_bytes"][v.name] = value;
    else
      point[v.name] = value;
  }
}

} // namespace

nlohmann::json pickJson(Renderer& renderer, lod::LodScene& scene, uint32_t x, uint32_t y) {
  std::optional<Renderer::LodPixel> at;
  try {
    at = renderer.lodPointAt(x, y);
  } catch (const InputError& e) {
    return {{"pixel", {x, y}}, {"point", std::string("unavailable: ") + e.what()}};
  }
  if (!at) return pickJson(PointCloud(), x, y, true, std::nullopt);
  const lod::NodeInfo& node = scene.hierarchy().node(at->node).info;
  // Sources whose points carry more than the record fields (cloud/lod_tails.h) give them with the node.
  auto* tailed = dynamic_cast<lod::NodeTails*>(&scene.source());
  if (tailed && tailed->tailFormat().bytes() == 0) tailed = nullptr;
  std::vector<uint8_t> tails;
  const std::vector<PointRecord> records =
      tailed ? tailed->readNodeTails(node, tails) : scene.source().readNode(node);
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
  nlohmann::json& p = j["point"];
  p["node"] = node.key.potreeName();
  const uint32_t tailBytes = tailed ? tailed->tailFormat().bytes() : 0;
  if (tailBytes > 0 && tails.size() >= (at->index + 1) * tailBytes)
    addTailValues(p, tailed->tailValues(tails.data() + at->index * tailBytes));
  return j;
}

} // namespace pointrast

#include "report/pick_json.h"

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

} // namespace pointrast

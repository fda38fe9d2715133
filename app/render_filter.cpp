#include "render_filter.h"

#include <cerrno>
#include <cstdlib>

#include "base/error.h"
#include "render/clip_volumes.h"
#include "report/pick_json.h"

namespace pointrast::app {

PointFilter renderFilter(const FilterArgs& a) {
  PointFilter f = pointFilter(a);
  checkGpuClip(f);
  return f;
}

uint64_t filterLoadedCloud(PointCloud& cloud, const PointFilter& filter) {
  if (!filter.hasAttributeFilter()) return 0;
  requireFilterAttributes(filter, filterFields(cloud), cloud.source);
  PointFilter attributes = filter;
  attributes.boxes.clear();
  attributes.orientedBoxes.clear();
  attributes.polygons.clear();
  const Bounds bounds = cloud.bounds;
  const uint64_t before = cloud.size();
  applyFilter(cloud, attributes);
  // The whole cloud's bounds: the camera's overview and the origin stay those of the file.
  cloud.bounds = bounds;
  return before - cloud.size();
}

void checkOctreeFilter(const PointFilter& filter, const std::string& method) {
  if (filter.hasAttributeFilter())
    throw InputError("--classes, --returns, --intensity, --gps-time and --source-ids apply to clouds drawn "
                     "from memory; " +
                     method + " draws an octree, which takes clip volumes only");
  if (filter.hasClip() && filter.clipMode == ClipMode::Highlight)
    throw InputError("--clip-mode highlight tints the colors of a cloud drawn from memory; " + method +
                     " draws an octree: use --clip-mode inside or outside");
}

PixelPos parsePick(const std::string& text, uint32_t width, uint32_t height) {
  const std::string expects = "--pick expects X,Y, a pixel of the " + std::to_string(width) + "x" +
                              std::to_string(height) + " image (0,0 at the top left), got '" + text + "'";
  const size_t comma = text.find(',');
  if (comma == std::string::npos) throw InputError(expects);
  auto number = [&](const std::string& item, uint32_t limit) {
    if (item.empty() || item.size() > 6 || item.find_first_not_of("0123456789") != std::string::npos)
      throw InputError(expects);
    const unsigned long v = std::strtoul(item.c_str(), nullptr, 10);
    if (v >= limit) throw InputError(expects);
    return uint32_t(v);
  };
  return {number(text.substr(0, comma), width), number(text.substr(comma + 1), height)};
}

nlohmann::json pickJson(const PointCloud& cloud, PixelPos pixel, bool empty, std::optional<uint64_t> index) {
  return pointrast::pickJson(cloud, pixel.x, pixel.y, empty, index);
}

} // namespace pointrast::app

// The profile cut shared by `pointrast profile` and the viewers' profile panels.
#include "view/profile_tool.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "base/error.h"
#include "cloud/attribute_colors.h"
#include "cloud/octree.h"
#include "cloud/point_record.h"
#include "io/format_table.h"
#include "io/io_util.h"
#include "io/las/las_filter.h"
#include "io/las/las_format.h"
#include "io/reader.h"
#include "io/writer.h"
#include "render/profile_plot.h"

namespace pointrast::view {

namespace {

// One kept point: where it lies in the profile and what the CSV and the picture show of it.
struct Kept {
  ProfilePlace place;
  glm::dvec3 position{0};
  uint16_t intensity = 0;
  uint8_t classification = 0, returnNumber = 0;
  double gpsTime = 0;
  uint16_t rgb[3] = {0, 0, 0};
};

struct Collected {
  std::vector<Kept> points;
  bool hasGps = false, hasColor = false, hasClassification = false;
  int colorShift = 0; // 8 for 16-bit colors
};

bool isLasFamily(const io::FormatInfo* format) {
  if (!format) return false;
  const std::string name = format->name;
  return name == "LAS" || name == "LAZ" || name == "COPC";
}

// LAS, LAZ, COPC: every record read raw; the LAS output gets the kept records byte for byte.
Collected collectLas(const ProfileRequest& a, const std::string& lasOut, const ProfileLine& line,
                     const PointFilter& filter) {
  Collected c;
  io::LasConvertOptions options;
  options.progress = a.progress;
  options.filter = &filter;
  int pointFormat = 0;
  {
    io::detail::InputFile file(a.input);
    const bool compressed = io::detail::lasLooksCompressed(file);
    const io::detail::LasHeader hd = io::detail::readLasHeader(file, compressed);
    pointFormat = hd.pointFormat;
  }
  const int rgbOffset = io::detail::las::kRgbOffset[size_t(pointFormat)];
  c.hasGps = io::detail::lasGpsOffset(pointFormat) >= 0;
  c.hasColor = rgbOffset >= 0;
  c.hasClassification = true;
  uint16_t colorMax = 0;
  options.keep = [&](const uint8_t* record, const FilterPoint& p) {
    const std::optional<ProfilePlace> place = profilePlace(line, glm::dvec2(p.position));
    if (!place) return false;
    Kept k;
    k.place = *place;
    k.position = p.position;
    k.intensity = p.intensity;
    k.classification = p.classification;
    k.returnNumber = p.returnNumber;
    k.gpsTime = p.gpsTime;
    if (rgbOffset >= 0)
      for (int i = 0; i < 3; ++i) {
        k.rgb[i] = io::detail::loadLE<uint16_t>(record + rgbOffset + 2 * i);
        colorMax = std::max(colorMax, k.rgb[i]);
      }
    c.points.push_back(k);
    return true;
  };
  io::convertLasFile(a.input, lasOut, options);
  c.colorShift = colorMax > 255 ? 8 : 0;
  return c;
}

// Octrees (Potree, EPT) node by node; other formats loaded whole. The LAS output holds their records.
Collected collectRecords(const ProfileRequest& a, const io::FormatInfo* format, const std::string& lasOut,
                         const ProfileLine& line, const PointFilter& filter) {
  Collected c;
  std::unique_ptr<lod::NodeSource> source;
  PointCloud cloud;
  glm::dvec3 scale, offset;
  RecordFields fields;
  if (format && format->openNodes) {
    source = format->openNodes(a.input);
    scale = source->metadata().scale;
    offset = source->metadata().offset;
    fields = source->metadata().fields;
  } else {
    io::ReadOptions options;
    options.progress = a.progress;
    cloud = io::readCloud(a.input, options);
    scale = cloud.scale;
    offset = cloud.offset;
    fields = recordFieldsOf(cloud);
  }
  FilterNeeds has;
  has.classification = fields.classification;
  has.returnNumber = fields.returnNumber;
  has.intensity = fields.intensity;
  has.pointSourceId = fields.pointSourceId;
  requireFilterAttributes(filter, has, std::filesystem::path(a.input).filename().string());
  c.hasColor = fields.color;
  c.hasClassification = fields.classification;
  std::optional<io::LasRecordWriter> writer;
  if (!lasOut.empty()) writer.emplace(lasOut, scale, offset, fields, io::LasFlavor::Las12Pf3);
  uint16_t colorMax = 0;
  auto take = [&](const std::vector<PointRecord>& records) {
    std::vector<PointRecord> kept;
    for (const PointRecord& r : records) {
      FilterPoint p;
      p.position = glm::dvec3(r.x, r.y, r.z) * scale + offset;
      p.classification = r.classification;
      p.returnNumber = r.returnNumber;
      p.intensity = r.intensity;
      p.pointSourceId = r.pointSourceId;
      if (!passes(filter, p)) continue;
      const std::optional<ProfilePlace> place = profilePlace(line, glm::dvec2(p.position));
      if (!place) continue;
      Kept k;
      k.place = *place;
      k.position = p.position;
      k.intensity = r.intensity;
      k.classification = r.classification;
      k.returnNumber = r.returnNumber;
      for (int i = 0; i < 3; ++i) {
        k.rgb[i] = r.rgb[i];
        colorMax = std::max(colorMax, r.rgb[i]);
      }
      c.points.push_back(k);
      kept.push_back(r);
    }
    if (writer) writer->write(kept.data(), kept.size());
  };
  if (source) {
    const Bounds strip = profileBounds(line);
    lod::forEachNode(*source, [&](const lod::NodeInfo& node) {
      const Bounds cube = source->metadata().nodeCube(node.key);
      const double grow = 2 * std::max({scale.x, scale.y, scale.z});
      // A node whose cube misses the strip's x/y bounds holds none of its points, nor does its subtree.
      if (cube.max.x + grow < strip.min.x || cube.min.x - grow > strip.max.x ||
          cube.max.y + grow < strip.min.y || cube.min.y - grow > strip.max.y)
        return false;
      take(source->readNode(node));
      return true;
    });
  } else {
    std::vector<PointRecord> records(size_t(cloud.size()));
    loadRecords(cloud, 0, records.size(), records.data());
    take(records);
  }
  if (writer) writer->commit();
  c.colorShift = source ? (colorMax > 255 ? 8 : 0) : 0;
  return c;
}

void writeCsv(const std::string& path, const Collected& c) {
  io::detail::PartialFile out(path);
  std::string text = "distance,elevation,x,y,z,intensity,classification,return_number";
  if (c.hasGps) text += ",gps_time";
  if (c.hasColor) text += ",r,g,b";
  text += "\n";
  char line[512];
  for (const Kept& k : c.points) {
    int n = std::snprintf(line, sizeof line, "%.6f,%.6f,%.6f,%.6f,%.6f,%u,%u,%u", k.place.distance,
                          k.position.z, k.position.x, k.position.y, k.position.z, unsigned(k.intensity),
                          unsigned(k.classification), unsigned(k.returnNumber));
    if (c.hasGps) n += std::snprintf(line + n, sizeof line - size_t(n), ",%.6f", k.gpsTime);
    if (c.hasColor)
      n += std::snprintf(line + n, sizeof line - size_t(n), ",%u,%u,%u", unsigned(k.rgb[0]),
                         unsigned(k.rgb[1]), unsigned(k.rgb[2]));
    line[n++] = '\n';
    text.append(line, size_t(n));
    if (text.size() > (1u << 20)) {
      out.write(text.data(), text.size());
      text.clear();
    }
  }
  out.write(text.data(), text.size());
  out.commit();
}

// Colors of the picture: the file's colors when it has any that are not all black, else the ASPRS
// classes, else elevation.
std::vector<uint32_t> drawPicture(const Collected& c, const ProfileLine& line, uint32_t w, uint32_t h) {
  bool colors = false;
  for (const Kept& k : c.points)
    if (c.hasColor && (k.rgb[0] | k.rgb[1] | k.rgb[2])) {
      colors = true;
      break;
    }
  double zMin = std::numeric_limits<double>::infinity(), zMax = -zMin;
  for (const Kept& k : c.points) {
    zMin = std::min(zMin, k.position.z);
    zMax = std::max(zMax, k.position.z);
  }
  std::vector<ProfileSample> samples;
  samples.reserve(c.points.size());
  for (const Kept& k : c.points) {
    ProfileSample s;
    s.distance = k.place.distance;
    s.elevation = k.position.z;
    s.depth = k.place.offset;
    if (colors)
      s.color = packRgba((k.rgb[0] >> c.colorShift) & 0xFF, (k.rgb[1] >> c.colorShift) & 0xFF,
                         (k.rgb[2] >> c.colorShift) & 0xFF);
    else if (c.hasClassification)
      s.color = classificationColor(k.classification);
    else
      s.color = elevationColor(zMax > zMin ? (k.position.z - zMin) / (zMax - zMin) : 0.5);
    samples.push_back(s);
  }
  ProfilePlot plot;
  plot.width = w;
  plot.height = h;
  plot.length = profileLength(line);
  return plotProfile(samples, plot);
}

} // namespace

ProfileResult cutProfile(const ProfileRequest& request) {
  assert(request.line.vertices.size() >= 2 && request.line.width > 0 && profileLength(request.line) > 0);
  const std::string lasOut = request.las;
  if (!lasOut.empty()) {
    const std::filesystem::path ext = std::filesystem::path(lasOut).extension();
    if (ext != ".las" && ext != ".laz")
      throw InputError(lasOut + ": the profile's points are written as .las or .laz");
  }
  const io::FormatInfo* format = io::detectFormat(request.input);
  const Collected c = isLasFamily(format)
                          ? collectLas(request, lasOut, request.line, request.filter)
                          : collectRecords(request, format, lasOut, request.line, request.filter);
  if (!request.csv.empty()) writeCsv(request.csv, c);
  ProfileResult result;
  result.points = c.points.size();
  if (request.imageWidth > 0 && request.imageHeight > 0)
    result.pixels = drawPicture(c, request.line, request.imageWidth, request.imageHeight);
  return result;
}

std::vector<glm::dvec2> parseProfileVertices(const std::string& text, const std::string& option,
                                             size_t maxVertices) {
  std::vector<double> v;
  size_t at = 0;
  const std::string expects = option + " expects x1,y1,x2,y2[,...] (two or more x,y vertices), got '" +
                              (text.size() > 80 ? text.substr(0, 80) + "..." : text) + "'";
  for (;;) {
    const size_t comma = text.find(',', at);
    const std::string item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(x)) throw InputError(expects);
    v.push_back(x);
    if (v.size() > 2 * maxVertices)
      throw InputError(option + " has more than " + std::to_string(maxVertices) + " vertices");
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  if (v.size() < 4 || v.size() % 2 != 0) throw InputError(expects);
  std::vector<glm::dvec2> vertices;
  for (size_t i = 0; i < v.size(); i += 2)
    vertices.emplace_back(v[i], v[i + 1]);
  return vertices;
}

} // namespace pointrast::view

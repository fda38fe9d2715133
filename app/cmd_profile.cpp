// pointrast profile IN --line x1,y1,x2,y2[,...] --width W [-o PNG] [--las|--laz OUT] [--csv OUT] [filters]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "base/error.h"
#include "base/progress.h"
#include "cloud/attribute_colors.h"
#include "cloud/profile.h"
#include "commands.h"
#include "input.h"
#include "io/format_table.h"
#include "io/io_util.h"
#include "io/las/las_filter.h"
#include "io/las/las_format.h"
#include "io/writer.h"
#include "options.h"
#include "render/profile_plot.h"

namespace pointrast::app {

namespace {

struct ProfileArgs {
  std::string input, line, png, las, laz, csv, size = "1200x500";
  double width = 0;
  bool quiet = false;
  FilterArgs filters;
};

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

ProfileLine parseLine(const ProfileArgs& a) {
  ProfileLine line;
  std::vector<double> v;
  size_t at = 0;
  const std::string expects =
      "--line expects x1,y1,x2,y2[,...] (two or more x,y vertices), got '" + a.line + "'";
  for (;;) {
    const size_t comma = a.line.find(',', at);
    const std::string item = a.line.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    char* end = nullptr;
    const double x = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(x)) throw InputError(expects);
    v.push_back(x);
    if (comma == std::string::npos) break;
    at = comma + 1;
  }
  if (v.size() < 4 || v.size() % 2 != 0) throw InputError(expects);
  for (size_t i = 0; i < v.size(); i += 2)
    line.vertices.emplace_back(v[i], v[i + 1]);
  if (!(a.width > 0) || !std::isfinite(a.width)) throw InputError("--width must be a positive length");
  line.width = a.width;
  if (!(profileLength(line) > 0)) throw InputError("--line has no length (its vertices coincide)");
  return line;
}

void parseSize(const std::string& text, uint32_t& w, uint32_t& h) {
  unsigned long x = 0, y = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lux%lu%c", &x, &y, &tail) != 2 || x < 200 || y < 120 || x > 16384 ||
      y > 16384)
    throw InputError("--size expects WxH, 200x120 to 16384x16384, got '" + text + "'");
  w = uint32_t(x);
  h = uint32_t(y);
}

bool isLasFamily(const io::FormatInfo* format) {
  if (!format) return false;
  const std::string name = format->name;
  return name == "LAS" || name == "LAZ" || name == "COPC";
}

// LAS, LAZ, COPC: every record read raw; the LAS output gets the kept records byte for byte.
Collected collectLas(const ProfileArgs& a, const std::string& lasOut, const ProfileLine& line,
                     const PointFilter& filter) {
  Collected c;
  io::LasConvertOptions options;
  options.progress = !a.quiet;
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
Collected collectRecords(const ProfileArgs& a, const io::FormatInfo* format, const std::string& lasOut,
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
    InputSpec spec;
    spec.source = a.input;
    spec.progress = !a.quiet;
    cloud = loadInput(spec);
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
  if (!lasOut.empty()) writer.emplace(lasOut, scale, offset, fields, lasFlavorFor(lasOut, 0));
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
void writePicture(const ProfileArgs& a, const Collected& c, const ProfileLine& line) {
  uint32_t w = 0, h = 0;
  parseSize(a.size, w, h);
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
  const std::vector<uint32_t> pixels = plotProfile(samples, plot);
  io::writePng(a.png, w, h, pixels.data());
}

} // namespace

Command addProfile(CLI::App& app) {
  auto a = std::make_shared<ProfileArgs>();
  CLI::App* cmd =
      app.add_subcommand("profile", "Cut a profile (cross section) along a line: PNG, LAS/LAZ, CSV");
  cmd->footer(
      "\nThe profile holds the points whose horizontal (x/y) distance to the line is at most W/2: the\n"
      "distance to the nearest point of the nearest segment, perpendicular to the segment where the foot\n"
      "of the perpendicular falls within it, else to the segment's nearer end. The strip is W wide along\n"
      "every segment, with half-disc caps at the line's ends and round joints. A point's distance along\n"
      "the line is the length of the line up to that nearest point. The filter options apply as well.\n"
      "Outputs: -o a PNG side view (x: distance along the line, y: elevation; nearer points, by their\n"
      "offset to the right of the line's direction, cover farther ones; colors from the file, else the\n"
      "ASPRS classes, else elevation), --las/--laz the kept point records unchanged (LAS, LAZ, COPC input:\n"
      "byte for byte, header counts and bounds for what was kept), --csv one row per point: distance,\n"
      "elevation, x, y, z, intensity, classification, return_number, gps_time (when the file has it),\n"
      "r, g, b (when it has colors, as stored).\n\n"
      "Examples:\n"
      "  pointrast profile autzen.laz --line 636100,849200,637100,849300 --width 4 -o cut.png\n"
      "  pointrast profile city.copc.laz --line 10,10,60,10,60,80 --width 2 --classes 2,6 --csv cut.csv");
  cmd->add_option("IN", a->input,
                  "Point cloud file (" + io::formatList(io::FormatUse::Cloud) +
                      ") or Potree 2.0 octree folder")
      ->required();
  cmd->add_option("--line", a->line, "The polyline, x1,y1,x2,y2[,...] in the file's coordinates")->required();
  cmd->add_option("--width", a->width, "Width of the strip (the points within width/2 of the line)")
      ->required();
  cmd->add_option("-o,--output", a->png, "PNG side view to write");
  cmd->add_option("--size", a->size, "Size of the PNG, WxH pixels")->capture_default_str();
  cmd->add_option("--las", a->las, "LAS file to write with the profile's points");
  cmd->add_option("--laz", a->laz, "LAZ file to write with the profile's points");
  cmd->add_option("--csv", a->csv, "CSV file to write, one row per point");
  cmd->add_flag("-q,--quiet", a->quiet, "No progress lines");
  addFilterOptions(*cmd, a->filters);
  return [a] {
    Progress::setEnabled(!a->quiet);
    const ProfileLine line = parseLine(*a);
    const PointFilter filter = pointFilter(a->filters);
    if (!a->las.empty() && !a->laz.empty()) throw InputError("--las and --laz: give one of them");
    if (a->png.empty() && a->las.empty() && a->laz.empty() && a->csv.empty())
      throw InputError("nothing to write: give -o PNG, --las, --laz or --csv");
    if (!a->las.empty() && std::filesystem::path(a->las).extension() != ".las")
      throw InputError(a->las + ": --las writes a .las file");
    if (!a->laz.empty() && std::filesystem::path(a->laz).extension() != ".laz")
      throw InputError(a->laz + ": --laz writes a .laz file");
    if (!a->png.empty()) {
      uint32_t w = 0, h = 0;
      parseSize(a->size, w, h);
      if (std::filesystem::path(a->png).extension() != ".png")
        throw InputError(a->png + ": -o writes a .png file");
    }
    if (!pathExists(a->input)) throw InputError(a->input + ": no such file or folder");
    const std::string lasOut = a->las.empty() ? a->laz : a->las;
    const io::FormatInfo* format = io::detectFormat(a->input);
    const Collected c = isLasFamily(format) ? collectLas(*a, lasOut, line, filter)
                                            : collectRecords(*a, format, lasOut, line, filter);
    if (!a->csv.empty()) writeCsv(a->csv, c);
    if (!a->png.empty()) writePicture(*a, c, line);
    if (!a->quiet)
      std::printf("profile: %s points within %g of a %g long line\n",
                  humanCount(double(c.points.size())).c_str(), 0.5 * line.width, profileLength(line));
    return 0;
  };
}

} // namespace pointrast::app

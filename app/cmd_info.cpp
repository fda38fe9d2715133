// pointrast info FILE [--json] | info --devices
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "cli_util.h"
#include "base/text.h"
#include "commands.h"
#include "gpu/context.h"
#include "input.h"
#include "io/format_table.h"
#include "io/particles/particles_io.h"
#include "io/reader.h"

namespace pointrast::app {

namespace {

struct InfoArgs {
  std::string input;
  uint32_t frame = 0;
  bool json = false, devices = false;
};

int listDevicesCommand(bool json) {
  std::vector<gpu::DeviceInfo> devices = gpu::listDevices();
  nlohmann::json list = nlohmann::json::array();
  for (size_t i = 0; i < devices.size(); ++i) {
    const gpu::DeviceInfo& d = devices[i];
    std::string api = std::to_string(VK_API_VERSION_MAJOR(d.apiVersion)) + "." +
                      std::to_string(VK_API_VERSION_MINOR(d.apiVersion)) + "." +
                      std::to_string(VK_API_VERSION_PATCH(d.apiVersion));
    if (json)
      list.push_back(
          {{"index", i}, {"name", d.name}, {"type", d.typeName}, {"vulkan", api}, {"driver", d.driver}});
    else
      std::printf("%zu: %s (%s, Vulkan %s, %s)\n", i, d.name.c_str(), d.typeName.c_str(), api.c_str(),
                  d.driver.c_str());
  }
  if (json) std::printf("%s\n", jsonText(list).c_str());
  return 0;
}

nlohmann::json jsonVec(const glm::dvec3& v) {
  return {v.x, v.y, v.z};
}

std::string rgba(uint32_t c) {
  return std::to_string(c & 255) + "," + std::to_string((c >> 8) & 255) + "," +
         std::to_string((c >> 16) & 255) + "," + std::to_string(c >> 24);
}

// MMPLD: the headers of the file and of one frame, then what only a pass over the particles can tell
// (how many are usable, the bounds of their centers, the radius range).
int mmpldInfo(const InfoArgs& a, const io::FormatInfo& format) {
  const io::MmpldInfo info = io::probeMmpld(a.input, a.frame);
  io::MmpldReadOptions options;
  options.frame = a.frame;
  const io::MmpldStats stats = io::scanMmpld(a.input, options);
  const std::string version = std::to_string(info.version / 100) + "." + std::to_string(info.version % 100);
  if (a.json) {
    nlohmann::json j;
    j["file"] = a.input;
    j["format"] = format.name;
    j["version"] = version;
    j["frames"] = info.frames;
    j["frame"] = info.frame;
    j["timestamp"] = info.hasTimestamp ? nlohmann::json(info.timestamp) : nlohmann::json();
    j["bounds_min"] = jsonVec(info.bbox.min);
    j["bounds_max"] = jsonVec(info.bbox.max);
    j["clip_min"] = jsonVec(info.clipBox.min);
    j["clip_max"] = jsonVec(info.clipBox.max);
    j["lists"] = nlohmann::json::array();
    for (const io::MmpldList& list : info.lists) {
      nlohmann::json l = {{"vertex", io::mmpldVertexName(list.vertex)},
                          {"color", io::mmpldColorName(list.color)},
                          {"particles", list.count}};
      if (list.vertex != io::MmpldVertex::FloatXyzr && list.hasPositions())
        l["global_radius"] = list.globalRadius;
      if (list.color == io::MmpldColor::None)
        l["global_color"] = {list.globalColor & 255, (list.globalColor >> 8) & 255,
                             (list.globalColor >> 16) & 255, list.globalColor >> 24};
      if (list.color == io::MmpldColor::FloatI || list.color == io::MmpldColor::DoubleI)
        l["intensity_range"] = {list.intensityMin, list.intensityMax};
      if (list.hasBounds) {
        l["bounds_min"] = jsonVec(list.bounds.min);
        l["bounds_max"] = jsonVec(list.bounds.max);
      }
      j["lists"].push_back(l);
    }
    j["particles"] = stats.particles;
    j["dropped"] = stats.dropped;
    if (stats.particles > 0) {
      j["centers_min"] = jsonVec(stats.centers.min);
      j["centers_max"] = jsonVec(stats.centers.max);
      j["radius_min"] = stats.radiusMin;
      j["radius_max"] = stats.radiusMax;
    }
    std::printf("%s\n", jsonText(j).c_str());
    return 0;
  }
  std::printf("file:    %s\n", printableLine(a.input).c_str()); // one line whatever the name
  std::printf("format:  MMPLD %s (%u), %u frame%s\n", version.c_str(), info.version, info.frames,
              info.frames == 1 ? "" : "s");
  std::printf("frame:   %u, %zu list%s", info.frame, info.lists.size(), info.lists.size() == 1 ? "" : "s");
  if (info.hasTimestamp) std::printf(", timestamp %g", double(info.timestamp));
  if (info.timestampMissing) std::printf(", no timestamp (1.3 as older MegaMol wrote it)");
  std::printf("\n");
  const auto box = [](const Bounds& b) {
    char line[200];
    std::snprintf(line, sizeof line, "%.6f, %.6f, %.6f .. %.6f, %.6f, %.6f", b.min.x, b.min.y, b.min.z,
                  b.max.x, b.max.y, b.max.z);
    return std::string(line);
  };
  std::printf("bounds:  %s (header)\n", box(info.bbox).c_str());
  std::printf("clip:    %s (header)\n", box(info.clipBox).c_str());
  for (size_t l = 0; l < info.lists.size(); ++l) {
    const io::MmpldList& list = info.lists[l];
    std::string line = std::string(io::mmpldVertexName(list.vertex)) + " + " +
                       io::mmpldColorName(list.color) + ", " + std::to_string(list.count) + " particles";
    if (!list.hasPositions()) line += " (no positions: skipped)";
    if (list.hasPositions() && list.vertex != io::MmpldVertex::FloatXyzr) {
      char radius[48];
      std::snprintf(radius, sizeof radius, ", radius %g", double(list.globalRadius));
      line += radius;
    }
    if (list.color == io::MmpldColor::None) line += ", color " + rgba(list.globalColor);
    if (list.color == io::MmpldColor::FloatI || list.color == io::MmpldColor::DoubleI) {
      char range[80];
      std::snprintf(range, sizeof range, ", intensity %g .. %g", double(list.intensityMin),
                    double(list.intensityMax));
      line += range;
    }
    if (list.hasBounds) line += ", bounds " + box(list.bounds);
    std::printf("%-8s %s\n", ("list " + std::to_string(l) + ":").c_str(), line.c_str());
  }
  std::printf("particles: %llu", static_cast<unsigned long long>(stats.particles));
  if (stats.dropped)
    std::printf(" (%llu dropped: NaN, infinite or bad radius)",
                static_cast<unsigned long long>(stats.dropped));
  std::printf("\n");
  if (stats.particles > 0) {
    std::printf("centers: %s\n", box(stats.centers).c_str());
    std::printf("radius:  %g .. %g\n", double(stats.radiusMin), double(stats.radiusMax));
  }
  return 0;
}

int runInfo(const InfoArgs& a) {
  if (a.devices) return listDevicesCommand(a.json);
  if (a.input.empty()) throw InputError("info needs a FILE (or --devices)");
  if (!pathExists(a.input)) throw InputError(a.input + ": no such file or folder");
  const io::FormatInfo* format = io::detectFormat(a.input);
  if (format && format->content == io::FormatContent::Particles) return mmpldInfo(a, *format);
  io::FileInfo info = io::probeFile(a.input);
  if (a.json) {
    nlohmann::json j;
    j["file"] = a.input;
    j["format"] = info.format->name;
    j["detail"] = info.formatDetail;
    j["points"] = info.pointCount;
    if (!info.bounds.empty()) {
      j["bounds_min"] = {info.bounds.min.x, info.bounds.min.y, info.bounds.min.z};
      j["bounds_max"] = {info.bounds.max.x, info.bounds.max.y, info.bounds.max.z};
    }
    j["bounds_from_header"] = info.boundsFromHeader;
    if (info.scale != glm::dvec3(0)) {
      j["scale"] = {info.scale.x, info.scale.y, info.scale.z};
      j["offset"] = {info.offset.x, info.offset.y, info.offset.z};
    }
    j["has_color"] = info.hasColor;
    if (info.hasColor) j["color_bits"] = info.colorBits;
    for (const auto& [key, value] : info.extra)
      j["extra"][key] = value;
    std::printf("%s\n", jsonText(j).c_str());
    return 0;
  }
  std::printf("file:    %s\n", printableLine(a.input).c_str()); // one line whatever the name
  std::printf("format:  %s\n", info.formatDetail.c_str());
  std::printf("points:  %llu\n", static_cast<unsigned long long>(info.pointCount));
  if (!info.bounds.empty()) {
    std::printf("bounds:  %.6f, %.6f, %.6f .. %.6f, %.6f, %.6f%s\n", info.bounds.min.x, info.bounds.min.y,
                info.bounds.min.z, info.bounds.max.x, info.bounds.max.y, info.bounds.max.z,
                info.boundsFromHeader ? " (header)" : "");
  }
  if (info.scale != glm::dvec3(0)) {
    std::printf("scale:   %g, %g, %g\n", info.scale.x, info.scale.y, info.scale.z);
    std::printf("offset:  %.6f, %.6f, %.6f\n", info.offset.x, info.offset.y, info.offset.z);
  }
  if (info.hasColor)
    std::printf("color:   RGB, %d-bit\n", info.colorBits);
  else
    std::printf("color:   none\n");
  for (const auto& [key, value] : info.extra)
    std::printf("%-8s %s\n", (key + ":").c_str(), value.c_str());
  return 0;
}

// "  LAS    .las    point cloud" per row of the format table: what `info`, `render` and `convert` read.
std::string formatHelp() {
  std::string help;
  for (const io::FormatInfo& f : io::formatTable()) {
    std::string what;
    if (f.content == io::FormatContent::Particles) what = "particles (spheres)";
    if (f.read) what = "point cloud";
    if (f.openPoints) what += ", streamed";
    if (f.openNodes) what += std::string(what.empty() ? "" : ", ") + "level-of-detail octree";
    if (what.empty()) what = "recognised, not read (says why)";
    char line[160];
    std::snprintf(line, sizeof line, "  %-11s %-20s %s\n", f.name, *f.extensions ? f.extensions : "(folder)",
                  what.c_str());
    help += line;
  }
  return help;
}

} // namespace

Command addInfo(CLI::App& app) {
  auto a = std::make_shared<InfoArgs>();
  CLI::App* cmd =
      app.add_subcommand("info", "Show what a point cloud or particle file holds, or list Vulkan devices");
  cmd->footer(
      "\nReads the header (and for LAS the color values, to tell 8-bit from 16-bit color). For MMPLD\n"
      "particle files: the version, frames, each list of one frame (vertex and color type, count,\n"
      "global radius or color, intensity range), then from a pass over its particles how many are\n"
      "usable, the bounds of their centers and the radius range. For a level-of-detail octree: points,\n"
      "nodes, depth, spacing, attributes, encoding, bounds and its writer.\n"
      "\nFormats (recognised by their content; text formats, which have no signature, by extension):\n" +
      formatHelp() +
      "\nExamples:\n  pointrast info autzen.las\n  pointrast info autzen.las --json\n"
      "  pointrast info particles.mmpld --frame 3\n  pointrast info octree/\n  pointrast info --devices");
  cmd->add_option("FILE", a->input,
                  "A point cloud (" + io::formatList(io::FormatUse::Cloud) + ") or particle (" +
                      io::formatList(io::FormatUse::Particles) + ") file, or an octree folder (" +
                      io::formatList(io::FormatUse::Octree) + ")");
  cmd->add_option("--frame", a->frame, "MMPLD: the frame to describe")->capture_default_str();
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->add_flag("--devices", a->devices, "List the Vulkan devices (indices for --device)");
  return [a] { return runInfo(*a); };
}

} // namespace pointrast::app

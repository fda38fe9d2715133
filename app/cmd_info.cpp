// pointrast info FILE [--json] | info --devices
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "base/error.h"
#include "commands.h"
#include "gpu/context.h"
#include "io/reader.h"

namespace pointrast::app {

namespace {

struct InfoArgs {
  std::string input;
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
  if (json) std::printf("%s\n", list.dump().c_str());
  return 0;
}

int runInfo(const InfoArgs& a) {
  if (a.devices) return listDevicesCommand(a.json);
  if (a.input.empty()) throw InputError("info needs a FILE (or --devices)");
  if (!std::filesystem::exists(a.input)) throw InputError(a.input + ": no such file");
  io::FileInfo info = io::probeFile(a.input);
  if (a.json) {
    nlohmann::json j;
    j["file"] = a.input;
    j["format"] = io::formatName(info.format);
    j["detail"] = info.formatDetail;
    j["points"] = info.pointCount;
    if (!info.bounds.empty()) {
      j["bounds_min"] = {info.bounds.min.x, info.bounds.min.y, info.bounds.min.z};
      j["bounds_max"] = {info.bounds.max.x, info.bounds.max.y, info.bounds.max.z};
    }
    j["bounds_from_header"] = info.boundsFromHeader;
    if (info.format == io::Format::Las) {
      j["scale"] = {info.scale.x, info.scale.y, info.scale.z};
      j["offset"] = {info.offset.x, info.offset.y, info.offset.z};
    }
    j["has_color"] = info.hasColor;
    if (info.hasColor) j["color_bits"] = info.colorBits;
    for (const auto& [key, value] : info.extra)
      j["extra"][key] = value;
    std::printf("%s\n", j.dump().c_str());
    return 0;
  }
  std::printf("file:    %s\n", a.input.c_str());
  std::printf("format:  %s\n", info.formatDetail.c_str());
  std::printf("points:  %llu\n", static_cast<unsigned long long>(info.pointCount));
  if (!info.bounds.empty()) {
    std::printf("bounds:  %.6f, %.6f, %.6f .. %.6f, %.6f, %.6f%s\n", info.bounds.min.x, info.bounds.min.y,
                info.bounds.min.z, info.bounds.max.x, info.bounds.max.y, info.bounds.max.z,
                info.boundsFromHeader ? " (header)" : "");
  }
  if (info.format == io::Format::Las) {
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

} // namespace

Command addInfo(CLI::App& app) {
  auto a = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "Show what a point cloud file holds, or list Vulkan devices");
  cmd->footer("\nReads the header (and for LAS the color values, to tell 8-bit from 16-bit color).\n"
              "Examples:\n  pointrast info autzen.las\n  pointrast info autzen.las --json\n  pointrast info "
              "--devices");
  cmd->add_option("FILE", a->input, "LAS/PLY/XYZ file");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->add_flag("--devices", a->devices, "List the Vulkan devices (indices for --device)");
  return [a] { return runInfo(*a); };
}

} // namespace pointrast::app

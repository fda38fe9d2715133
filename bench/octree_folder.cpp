#include "bench/octree_folder.h"

#include <chrono>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "bench/report_parts.h"
#include "io/lod_potree.h"
#include "io/potree.h"
#include "io/writer.h"

namespace pointrast::bench {

namespace {

uint64_t folderBytes(const std::filesystem::path& dir) {
  uint64_t bytes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.is_regular_file()) bytes += entry.file_size();
  return bytes;
}

std::string phasesText(const io::LodBuildReport& report) {
  std::string text;
  for (const lod::LodPhase& p : report.phases)
    text += (text.empty() ? "" : ", ") + p.name + " " + std::to_string(int(p.seconds + 0.5)) + " s";
  return text;
}

} // namespace

OctreeProvider octreeFolder(const std::filesystem::path& dir, bool progress) {
  return [dir, progress](const std::string& name, const std::function<const PointCloud&()>& points) {
    DatasetOctree o;
    o.path = dir / name;
    const std::filesystem::path record = dir / (name + ".build.json");
    if (std::filesystem::exists(o.path / "metadata.json")) {
      o.reused = true;
      std::ifstream in(record);
      if (in) {
        const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
        if (j.is_object()) {
          o.buildSeconds = j.value("seconds", 0.0);
          o.phases = j.value("phases", std::string());
        }
      }
    } else {
      std::filesystem::create_directories(dir);
      const auto start = std::chrono::steady_clock::now();
      const std::filesystem::path las = dir / (name + ".input.las");
      std::filesystem::remove_all(o.path);
      io::PotreeBuildReport report;
      try {
        io::writeLas(las, points(), io::LasFlavor::Las12Pf2);
        io::LodBuildOptions options;
        options.progress = progress;
        report = io::buildPotree({las}, o.path, options, {});
      } catch (...) {
        std::filesystem::remove(las);
        throw;
      }
      std::filesystem::remove(las);
      o.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      o.phases = "LAS written, then " + phasesText(report.build);
      writeAtomically(record,
                      nlohmann::json{{"seconds", o.buildSeconds}, {"phases", o.phases}}.dump() + "\n");
    }
    o.bytes = folderBytes(o.path);
    o.points = io::openPotree(o.path)->metadata().pointCount;
    return o;
  };
}

std::filesystem::path defaultOctreeFolder() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return std::filesystem::path(xdg) / "pointrast" / "octrees";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".cache" / "pointrast" / "octrees";
  return std::filesystem::temp_directory_path() / "pointrast-octrees";
}

} // namespace pointrast::bench

#include "bench/suites.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "base/error.h"

namespace pointrast::bench {

namespace {

// The 2021 paper's four data sets, as named in the authors' code (m-schuetz/compute_rasterizer) and
// sized as in the paper (796 M points = the 12.7 GB of its abstract at 16 B/point). Each gets the
// generator closest to how it was captured: airborne surveys of land -> terrain; laser scans of an
// object from the ground around it -> tls (scan-line order, density falling with distance).
constexpr SuiteEntry kPaper2021[] = {
    {"banyunibo", Scene::Tls, 4'000'000, "Candi Banyunibo, a temple scanned from the ground"},
    {"eclepens", Scene::Terrain, 47'000'000, "Eclepens, an aerial survey of a quarry and its land"},
    {"retz", Scene::Terrain, 145'000'000, "Retz, an aerial survey of a town (Riegl)"},
    {"endeavor", Scene::Tls, 796'000'000, "Space Shuttle Endeavour, terrestrial laser scans"},
};

constexpr uint64_t kMinScaledPoints = 1000;

} // namespace

std::span<const SuiteEntry> paper2021Suite() {
  return kPaper2021;
}

std::vector<std::string> suiteNames() {
  return {"paper2021"};
}

std::string shortCount(uint64_t points) {
  struct Unit {
    double size;
    const char* suffix;
  };
  for (Unit u : {Unit{1e9, "G"}, Unit{1e6, "M"}, Unit{1e3, "k"}}) {
    if (double(points) >= u.size) {
      double v = double(points) / u.size;
      char text[32];
      // Whole numbers stay whole (4M, 145M); others get the one decimal that tells them apart (1.5M).
      if (std::abs(v - std::round(v)) < 0.05 || v >= 100)
        std::snprintf(text, sizeof text, "%.0f%s", v, u.suffix);
      else
        std::snprintf(text, sizeof text, "%.1f%s", v, u.suffix);
      return text;
    }
  }
  return std::to_string(points);
}

std::vector<Dataset> suiteDatasets(std::string_view suite, double scale, uint64_t seed,
                                   const std::vector<std::string>& replacements) {
  if (suite != "paper2021") throw InputError("unknown suite '" + std::string(suite) + "'; choose paper2021");
  if (!(scale > 0) || !std::isfinite(scale)) throw InputError("--scale must be a positive number");
  std::vector<Dataset> datasets;
  for (const SuiteEntry& e : kPaper2021) {
    Dataset d;
    d.source = sceneName(e.scene);
    d.seed = seed;
    d.points = std::max<uint64_t>(kMinScaledPoints, uint64_t(std::llround(double(e.points) * scale)));
    d.name = std::string(e.name) + "-like";
    d.label = d.name + " (" + sceneName(e.scene) + ", " + shortCount(d.points) + ")";
    datasets.push_back(d);
  }
  for (const std::string& item : replacements) {
    size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw InputError("'" + item +
                       "': with --suite, a file replaces a stand-in as NAME=PATH (names: "
                       "banyunibo, eclepens, retz, endeavor)");
    std::string name = item.substr(0, eq), path = item.substr(eq + 1);
    bool found = false;
    for (size_t k = 0; k < datasets.size(); ++k) {
      if (name != kPaper2021[k].name && name != datasets[k].name) continue;
      Dataset& d = datasets[k];
      d = Dataset{};
      d.source = path;
      d.file = true;
      d.name = kPaper2021[k].name;
      d.label = d.name + " (" + std::filesystem::path(path).filename().string() + ")";
      found = true;
    }
    if (!found)
      throw InputError("'" + name +
                       "' is no data set of suite paper2021 (banyunibo, eclepens, retz, endeavor)");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": no such file");
  }
  return datasets;
}

} // namespace pointrast::bench

#include "bench/suites.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>

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

// The 2022 paper's data sets by size (its Table 1 and 2: 69 M, 279 M, 529 M seen from outside and from
// inside, 1,000 M; rendered at 2560 x 1140), in Morton order as the paper stores them; and a generated
// laser scan in its scan order and in Morton order (the paper's section on vertex order: batches of
// consecutive points in scan order are long strips, so fewer of them are culled or get by on few words).
// Generators as for paper2021: laser scans of objects and buildings -> tls, aerial surveys -> terrain.
constexpr SuiteEntry kPaper2022[] = {
    {"scan69m", Scene::Tls, 69'000'000, "a 69 M point terrestrial laser scan"},
    {"aerial279m", Scene::Terrain, 279'000'000, "a 279 M point aerial survey"},
    {"scan529m", Scene::Tls, 529'000'000, "a 529 M point laser scan, seen from outside and inside", true},
    {"aerial1g", Scene::Terrain, 1'000'000'000, "a 1,000 M point aerial survey"},
    {"tls-order", Scene::Tls, 100'000'000, "a generated laser scan in scan order and in Morton order", true,
     true},
};

// The lod suite's data set: the 1,000 M point aerial stand-in of paper2022 (same name, size and seed, so both
// suites share its octree): the LOD methods' sweeps, and the streaming run with 1/8 of its octree in GPU
// memory (a cloud 8x larger than the node cache).
constexpr SuiteEntry kLod[] = {
    {"aerial1g", Scene::Terrain, 1'000'000'000, "a 1,000 M point aerial survey, as an octree"},
};

// The vr2022 suite's data set: the 529 M point laser-scan stand-in of paper2022 (same name, size and seed, so
// both suites share its octree), as in the 2022 paper's VR section (a 529 M point octree in a headset).
constexpr SuiteEntry kVr2022[] = {
    {"scan529m", Scene::Tls, 529'000'000, "a 529 M point laser scan, as an octree seen in a headset"},
};

// The four particle data sets of the 2023 sphere study, at their sizes (306 M, 4 M, 30 M, 200 M particles,
// in this order), each drawn by the particle scene closest to what it shows:
// laser ablation of a metal (a crystal slab with a molten crater and ejected clusters), a Riemann shock tube
// (a dense block between two vapor regions), a drop and a fluid simulation (liquid droplets and filaments in
// a vapor; particles-drops for both, at their two sizes).
constexpr SphereSuiteEntry kSpheres2023[] = {
    {"laser", ParticleScene::Laser, 306'000'000, "laser ablation of a metal crystal (molecular dynamics)"},
    {"riemann", ParticleScene::Block, 4'000'000, "a Riemann shock tube: dense liquid between vapor regions"},
    {"drop", ParticleScene::Drops, 30'000'000, "a liquid drop breaking up in its vapor"},
    {"fluid", ParticleScene::Drops, 200'000'000, "a two-phase fluid: droplets and filaments in vapor"},
};

constexpr uint64_t kMinScaledPoints = 1000;

// The suites' defaults beyond their data sets (methods, orders, views, image size).
void paper2021Defaults(SuiteDefaults& d) {
  // The 2021 family and its hardware baseline: every method that reads the float layout. The batch
  // methods are the 2022 suite's (they can still be asked for with --methods).
  for (Method m : allMethods())
    if (m.info().layout == SceneLayout::Float) d.methods.push_back(m);
}

void paper2022Defaults(SuiteDefaults& d) {
  // The paper's comparison: the hardware baseline, its three batch methods and its two LOD methods on the
  // octrees of the same data, and the best 2021 methods.
  d.methods = {pointMethod("hw-points"), pointMethod("batch"),  pointMethod("batch-prefetch"),
               pointMethod("batch-hqs"), pointMethod("dedup"),  pointMethod("hqs"),
               pointMethod("lod"),       pointMethod("lod-hqs")};
  d.orders = {Order::Morton, Order::Original};
  d.views = {View::Overview, View::Closeup};
  d.width = 2560;
  d.height = 1140;
}

void lodDefaults(SuiteDefaults& d) {
  d.methods = {pointMethod("lod")};
  d.views = {View::Overview, View::Closeup};
  d.width = 2560;
  d.height = 1140;
}

void vr2022Defaults(SuiteDefaults& d) {
  d.methods = {pointMethod("lod-hqs"), pointMethod("lod")};
  d.views = {View::Closeup, View::Overview};
  d.width = 2478; // each eye's
  d.height = 2740;
}

// Every suite, in the order help and errors list them: a new suite is one row here (its data sets above,
// and a runner of its kind).
const Suite kSuites[] = {
    {"paper2021", SuiteKind::Points, kPaper2021, {}, paper2021Defaults, false},
    {"paper2022", SuiteKind::Points, kPaper2022, {}, paper2022Defaults, true},
    {"lod", SuiteKind::Lod, kLod, {}, lodDefaults, false},
    {"vr2022", SuiteKind::Vr, kVr2022, {}, vr2022Defaults, false},
    {"spheres2023", SuiteKind::Spheres, {}, kSpheres2023, nullptr, false},
};

// The suite named `name`; InputError naming every suite when there is none.
const Suite& suiteOf(std::string_view name) {
  if (const Suite* suite = findSuite(name)) return *suite;
  std::string names;
  for (size_t k = 0; k < std::size(kSuites); ++k)
    names += (k == 0 ? "" : k + 1 == std::size(kSuites) ? " or " : ", ") + std::string(kSuites[k].name);
  throw InputError("unknown suite '" + std::string(name) + "'; choose " + names);
}

// The point data sets of a suite; InputError for a particle suite.
std::span<const SuiteEntry> entriesOf(std::string_view name) {
  const Suite& suite = suiteOf(name);
  if (suite.kind == SuiteKind::Spheres)
    throw InputError(std::string(suite.name) + " is a particle suite: it has no point data sets or methods");
  return suite.points;
}

uint64_t scaled(uint64_t size, double scale) {
  if (!(scale > 0) || !std::isfinite(scale)) throw InputError("--scale must be a positive number");
  return std::max<uint64_t>(kMinScaledPoints, uint64_t(std::llround(double(size) * scale)));
}

std::string entryNames(std::span<const SuiteEntry> entries) {
  std::string names;
  for (const SuiteEntry& e : entries)
    names += (names.empty() ? "" : ", ") + std::string(e.name);
  return names;
}

} // namespace

std::span<const SuiteEntry> paper2021Suite() {
  return kPaper2021;
}

std::span<const SuiteEntry> paper2022Suite() {
  return kPaper2022;
}

std::span<const Suite> suites() {
  return kSuites;
}

const Suite* findSuite(std::string_view name) {
  for (const Suite& suite : kSuites)
    if (suite.name == name) return &suite;
  return nullptr;
}

std::vector<std::string> suiteNames() {
  std::vector<std::string> names;
  for (const Suite& suite : kSuites)
    names.push_back(suite.name);
  return names;
}

std::span<const SphereSuiteEntry> spheres2023Suite() {
  return kSpheres2023;
}

bool isLodSuite(std::string_view suite) {
  const Suite* found = findSuite(suite);
  return found && found->kind == SuiteKind::Lod;
}

bool isVrSuite(std::string_view suite) {
  const Suite* found = findSuite(suite);
  return found && found->kind == SuiteKind::Vr;
}

bool isSphereSuite(std::string_view suite) {
  const Suite* found = findSuite(suite);
  return found && found->kind == SuiteKind::Spheres;
}

std::vector<Dataset> sphereSuiteDatasets(std::string_view suite, double scale, uint64_t seed) {
  const Suite& found = suiteOf(suite);
  if (found.kind != SuiteKind::Spheres) throw InputError(std::string(found.name) + " is no particle suite");
  std::vector<Dataset> datasets;
  for (const SphereSuiteEntry& e : found.spheres) {
    Dataset d;
    d.source = particleSceneName(e.scene);
    d.seed = seed;
    d.points = scaled(e.particles, scale);
    d.name = std::string(e.name) + "-like";
    d.label = d.name + " (" + particleSceneName(e.scene) + ", " + shortCount(d.points) + ")";
    datasets.push_back(d);
  }
  return datasets;
}

SuiteDefaults suiteDefaults(std::string_view suite) {
  SuiteDefaults d;
  const Suite& found = suiteOf(suite);
  if (found.defaults) found.defaults(d);
  return d;
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
  const std::span<const SuiteEntry> entries = entriesOf(suite);
  const bool perDataset = suiteOf(suite).perDatasetOrdersAndViews;
  std::vector<Dataset> datasets;
  for (const SuiteEntry& e : entries) {
    Dataset d;
    d.source = sceneName(e.scene);
    d.seed = seed;
    d.points = scaled(e.points, scale);
    d.name = std::string(e.name) + (e.scanOrder ? "" : "-like");
    d.label = d.name + " (" + sceneName(e.scene) + ", " + shortCount(d.points) + ")";
    if (perDataset) {
      d.orders = e.scanOrder ? std::vector<Order>{Order::Original, Order::Morton}
                             : std::vector<Order>{Order::Morton};
      d.views =
          e.inside ? std::vector<View>{View::Overview, View::Closeup} : std::vector<View>{View::Overview};
    }
    datasets.push_back(d);
  }
  for (const std::string& item : replacements) {
    size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size())
      throw InputError("'" + item + "': with --suite, a file replaces a stand-in as NAME=PATH (names: " +
                       entryNames(entries) + ")");
    std::string name = item.substr(0, eq), path = item.substr(eq + 1);
    bool found = false;
    for (size_t k = 0; k < datasets.size(); ++k) {
      if (name != entries[k].name && name != datasets[k].name) continue;
      Dataset& d = datasets[k];
      const std::vector<Order> orders = d.orders;
      const std::vector<View> views = d.views;
      d = Dataset{};
      d.source = path;
      d.file = true;
      d.orders = orders;
      d.views = views;
      d.name = entries[k].name;
      d.label = d.name + " (" + std::filesystem::path(path).filename().string() + ")";
      found = true;
    }
    if (!found)
      throw InputError("'" + name + "' is no data set of suite " + std::string(suite) + " (" +
                       entryNames(entries) + ")");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": no such file");
  }
  return datasets;
}

} // namespace pointrast::bench

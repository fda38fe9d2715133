// Named benchmark suites. `paper2021` stands in for the data sets of "Rendering Point Clouds with
// Compute Shaders and Vertex Order Optimization" (Schuetz, Kerbl, Wimmer, EGSR 2021) with generated
// scenes of the same sizes; `paper2022` for those of "Software Rasterization of 2 Billion Points in Real
// Time" (Schuetz, Kerbl, Wimmer, HPG 2022), plus its scan order vs Morton order study; see suites.cpp for
// which generator stands in for which data set and why. `spheres2023` stands in for the particle data sets
// of "Efficient Sphere Rendering Revisited" (Gralka, Reina, Ertl, EGPGV 2023) with generated particle
// scenes, measured by bench/sphere_runner.h.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bench/runner.h"
#include "cloud/generate.h"
#include "cloud/particles_generate.h"

namespace pointrast::bench {

struct SuiteEntry {
  const char* name;     // "retz": the paper's data set
  Scene scene;          // the generator that stands in for it
  uint64_t points;      // the paper's size
  const char* acquired; // how the original was acquired, the reason for the generator
  // paper2022: measured from inside (the closeup view) as well as the overview, and in the original (scan)
  // order as well as Morton order. paper2021 measures every data set in every order and view.
  bool inside = false;
  bool scanOrder = false;
};

std::span<const SuiteEntry> paper2021Suite();
std::span<const SuiteEntry> paper2022Suite();

// A particle data set of a sphere suite and the particle scene that stands in for it.
struct SphereSuiteEntry {
  const char* name;      // "laser": the study's data set
  ParticleScene scene;   // the generator that resembles it
  uint64_t particles;    // the size measured
  const char* resembles; // what the original holds, the reason for the generator
};
std::span<const SphereSuiteEntry> spheres2023Suite();

// What a suite measures besides its data sets; the CLI takes these where no option says otherwise.
// Empty lists: every method, order or view.
struct SuiteDefaults {
  std::vector<Method> methods; // the columns of its tables
  std::vector<Order> orders;   // every order some data set is measured in
  std::vector<View> views;
  uint32_t width = 1920, height = 1080;
};

// Which runner measures a suite and writes its reports: the point runner (bench/runner.h, bench/report.h),
// the sphere runner (bench/sphere_runner.h), the lod suite's (bench/lod_suite.h) or the VR suite's
// (bench/vr_suite.h).
enum class SuiteKind { Points, Spheres, Lod, Vr };

// One suite: a row of the table in suites.cpp, all that names it anywhere.
struct Suite {
  const char* name;
  SuiteKind kind;
  std::span<const SuiteEntry> points;        // its point data sets (not Spheres)
  std::span<const SphereSuiteEntry> spheres; // its particle data sets (Spheres)
  void (*defaults)(SuiteDefaults&);          // its methods, orders, views and image size; null: none
  // Each data set carries its own orders and views (SuiteEntry::inside, scanOrder), as paper2022's do.
  bool perDatasetOrdersAndViews;
};
// Every suite, in the order help and errors list them.
std::span<const Suite> suites();
// The suite named `name`, null for none.
const Suite* findSuite(std::string_view name);
std::vector<std::string> suiteNames();
// Whether `suite` is the lod suite (bench/lod_suite.h: sweeps and streaming on octrees, its own runner).
bool isLodSuite(std::string_view suite);
// Whether `suite` is the vr2022 suite (bench/vr_suite.h: stereo frames on an octree, its own runner).
bool isVrSuite(std::string_view suite);
// Whether `suite` is a sphere suite (its data sets are particle sets, its runner the sphere runner).
bool isSphereSuite(std::string_view suite);
// The particle data sets of a sphere suite with every size multiplied by `scale` (at least 1000 particles
// each); Dataset::source is the particle scene's name. Throws InputError for an unknown suite or a bad
// scale.
std::vector<Dataset> sphereSuiteDatasets(std::string_view suite, double scale, uint64_t seed);

// Throws InputError for an unknown suite. A sphere suite has no point methods, orders or views.
SuiteDefaults suiteDefaults(std::string_view suite);

// The data sets of a suite with every size multiplied by `scale` (a quick smoke run: 0.001 gives
// 4 k .. 796 k points for paper2021; at least 1000 points each); paper2022's carry their orders and views.
// `replacements` are "NAME=PATH" items: the file at PATH replaces the stand-in NAME at its own size. Throws
// InputError for an unknown suite, a bad scale or a replacement naming no data set of the suite.
std::vector<Dataset> suiteDatasets(std::string_view suite, double scale, uint64_t seed,
                                   const std::vector<std::string>& replacements = {});

// "4M", "145M", "1.5G", "20k", "999": point counts in names and labels.
std::string shortCount(uint64_t points);

} // namespace pointrast::bench

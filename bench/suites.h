// Named benchmark suites. `paper2021` stands in for the data sets of "Rendering Point Clouds with
// Compute Shaders and Vertex Order Optimization" (Schuetz, Kerbl, Wimmer, EGSR 2021) with generated
// scenes of the same sizes; see suites.cpp for which generator stands in for which data set and why.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "bench/runner.h"
#include "cloud/generate.h"

namespace pointrast::bench {

struct SuiteEntry {
  const char* name;     // "retz": the paper's data set
  Scene scene;          // the generator that stands in for it
  uint64_t points;      // the paper's size
  const char* acquired; // how the original was acquired, the reason for the generator
};

std::span<const SuiteEntry> paper2021Suite();
std::vector<std::string> suiteNames();

// The data sets of a suite with every size multiplied by `scale` (a quick smoke run: 0.001 gives
// 4 k .. 796 k points; at least 1000 points each). `replacements` are "NAME=PATH" items: the file at
// PATH replaces the stand-in NAME at its own size. Throws InputError for an unknown suite, a bad scale
// or a replacement naming no data set of the suite.
std::vector<Dataset> suiteDatasets(std::string_view suite, double scale, uint64_t seed,
                                   const std::vector<std::string>& replacements = {});

// "4M", "145M", "1.5G", "20k", "999": point counts in names and labels.
std::string shortCount(uint64_t points);

} // namespace pointrast::bench

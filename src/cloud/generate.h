// Procedural scenes, deterministic for a given (scene, point count, seed) whatever the number of threads,
// generated on all hardware threads. Colors are RGB; positions quantized to 1 mm.
#pragma once

#include <cstdint>
#include <string_view>

#include "cloud/cloud.h"

namespace pointrast {

enum class Scene {
  Terrain, // aerial LiDAR: rolling ground, buildings with roofs and walls, trees; flight-strip scan order
  Tls,     // terrestrial scan: a few scanner positions, points in each scanner's scan-line order
};

// Parses "terrain" or "tls"; throws InputError naming the choices. isSceneName() does not throw.
Scene parseScene(std::string_view name);
bool isSceneName(std::string_view name);
const char* sceneName(Scene scene);

struct GenerateOptions {
  uint64_t points = 1'000'000;
  uint64_t seed = 1;
  bool progress = true;
  // Only points [first, first + count) of the scene of `points` points (a rank's share of a distributed
  // render): the same points the whole scene holds at those indices; bounds are the share's.
  uint64_t first = 0;
  uint64_t count = UINT64_MAX; // clamped to the scene's size
  // ASPRS classes as well (terrain: 2 ground, 5 high vegetation, 6 building; tls: 1), 1 byte a point more:
  // for class filters and the classification colors.
  bool classification = false;
};

// Throws InputError if the count cannot be held (more than 2^40 points or allocation would fail).
PointCloud generateScene(Scene scene, const GenerateOptions& options);

} // namespace pointrast

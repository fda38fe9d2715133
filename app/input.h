// What the commands take as input: a file, or the name of a generated scene.
#pragma once

#include <cstdint>
#include <string>

#include "cloud/cloud.h"
#include "cloud/order.h"

namespace pointrast::app {

struct InputSpec {
  std::string source;          // a path, or a scene name ("terrain", "tls"); empty = demo scene
  uint64_t points = 1'000'000; // for scenes
  uint64_t seed = 1;           // for scenes and shuffled orders
  Order order = Order::Original;
  bool progress = true;
};

// The built-in demo: the terrain scene, 1 M points, seed 1.
constexpr const char* kDemoScene = "terrain";
constexpr uint64_t kDemoPoints = 1'000'000;

// Reads the file or generates the scene, then applies the order. Throws InputError for a source that is
// neither an existing file nor a scene name.
PointCloud loadInput(const InputSpec& spec);

} // namespace pointrast::app

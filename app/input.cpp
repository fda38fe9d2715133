#include "input.h"

#include <filesystem>

#include "base/error.h"
#include "cloud/generate.h"
#include "io/reader.h"

namespace pointrast::app {

PointCloud loadInput(const InputSpec& spec) {
  PointCloud cloud;
  std::string source = spec.source.empty() ? kDemoScene : spec.source;
  std::error_code ec;
  if (std::filesystem::exists(source, ec)) {
    io::ReadOptions options;
    options.progress = spec.progress;
    cloud = io::readCloud(source, options);
  } else if (isSceneName(source)) {
    GenerateOptions options;
    options.points = spec.source.empty() ? kDemoPoints : spec.points;
    options.seed = spec.seed;
    options.progress = spec.progress;
    cloud = generateScene(parseScene(source), options);
  } else {
    throw InputError(source + ": no such file, and not a scene name (terrain, tls)");
  }
  reorder(cloud, spec.order, spec.seed);
  return cloud;
}

} // namespace pointrast::app

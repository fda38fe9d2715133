#include "cloud/generate.h"

#include <algorithm>
#include <new>
#include <optional>
#include <string>
#include <unistd.h>

#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "cloud/scene.h"

namespace pointrast {

namespace {
constexpr const char* kSceneNames[] = {"terrain", "tls"};
// Fixed block size (64 Ki points): the unit of work and of progress; results do not depend on it.
constexpr uint64_t kBlock = uint64_t(1) << 16;
constexpr uint64_t kMaxPoints = uint64_t(1) << 40;
constexpr uint64_t kBytesPerPoint = 3 * sizeof(int32_t) + sizeof(uint32_t);
} // namespace

Scene parseScene(std::string_view name) {
  for (int k = 0; k < 2; ++k)
    if (name == kSceneNames[k]) return static_cast<Scene>(k);
  throw InputError("unknown scene '" + std::string(name) + "' (choices: terrain, tls)");
}

bool isSceneName(std::string_view name) {
  return name == kSceneNames[0] || name == kSceneNames[1];
}

const char* sceneName(Scene scene) {
  return kSceneNames[static_cast<int>(scene)];
}

namespace detail {
std::unique_ptr<SceneGenerator> makeScene(Scene scene, uint64_t points, uint64_t seed) {
  return scene == Scene::Terrain ? makeTerrainScene(points, seed) : makeTlsScene(points, seed);
}
} // namespace detail

PointCloud generateScene(Scene scene, const GenerateOptions& options) {
  const uint64_t all = options.points;
  const uint64_t first = std::min(options.first, all);
  const uint64_t n = std::min(options.count, all - first);
  const std::string what = std::string(sceneName(scene)) + ", " + std::to_string(all) + " points, seed " +
                           std::to_string(options.seed);
  if (all > kMaxPoints)
    throw InputError("cannot generate " + what + ": at most 2^40 (" + std::to_string(kMaxPoints) +
                     ") points");
  // Refuse up front what cannot fit in physical memory, rather than being killed half way.
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && pageSize > 0 && double(n) * kBytesPerPoint > double(pages) * double(pageSize))
    throw InputError("cannot generate " + what + ": needs " + humanCount(double(n) * kBytesPerPoint) +
                     "B, more than this machine's memory (" + humanCount(double(pages) * double(pageSize)) +
                     "B)");

  PointCloud cloud;
  cloud.scale = glm::dvec3(detail::SceneGenerator::kScale);
  cloud.source = what;
  try {
    // Exactly 16 B per point, allocated once; generation writes in place.
    cloud.positions.resize(3 * n);
    cloud.colors.resize(n);
    if (options.classification) cloud.classification.resize(n);
  } catch (const std::bad_alloc&) {
    throw InputError("cannot generate " + what + ": out of memory");
  }
  auto generator = detail::makeScene(scene, all, options.seed);
  cloud.offset = generator->offset;
  std::optional<Progress> progress;
  if (options.progress) progress.emplace("generating " + std::string(sceneName(scene)), n);
  parallelBlocks(n, kBlock, [&](uint64_t, uint64_t begin, uint64_t end) {
    generator->generate(first + begin, end - begin, cloud.positions.data() + 3 * begin,
                        cloud.colors.data() + begin,
                        options.classification ? cloud.classification.data() + begin : nullptr);
    if (progress) progress->advance(end - begin);
  });
  if (progress) progress->finish();
  computeBounds(cloud);
  return cloud;
}

} // namespace pointrast

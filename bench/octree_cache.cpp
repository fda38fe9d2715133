#include "bench/octree_cache.h"

#include <signal.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>

#include "base/error.h"
#include "base/parallel.h"
#include "base/progress.h"
#include "bench/report.h"
#include "bench/report_parts.h"
#include "cloud/detail.h"
#include "cloud/lod_build.h"
#include "cloud/lod_grid.h"
#include "cloud/point_record.h"
#include "io/format_table.h"
#include "io/potree/lod_builder.h"
#include "io/potree/lod_potree.h"
#include "io/potree/potree.h"

namespace pointrast::bench {

namespace {

namespace fs = std::filesystem;

// Records handed to the builder per piece: pieces are converted and freed one by one, on all cores.
constexpr uint64_t kPiecePoints = uint64_t(1) << 20;
// What the in-memory build holds per point while records and their coded copies both exist (as the
// octree builder's own bound: 24 B record + 32 B item), and a thread's indexing scratch per chunk point.
constexpr uint64_t kBuildBytesPerPoint = 56, kIndexBytesPerPoint = 112;
// Potree 2.0 DEFAULT encoding: about the 24 B record per point in octree.bin; the hierarchy is small.
constexpr uint64_t kOctreeBytesPerPoint = 24;
constexpr uint64_t kSlackBytes = uint64_t(64) << 20;

std::string gb(uint64_t bytes) {
  return printf1("%.1f GB", double(bytes) * 1e-9);
}

std::string phasesText(const std::vector<lod::LodPhase>& phases) {
  std::string text;
  for (const lod::LodPhase& p : phases)
    text += (text.empty() ? "" : ", ") + p.name + " " +
            printf1(p.overlapped ? "(%.1f s, during index)" : "%.1f s", p.seconds);
  return text;
}

uint64_t folderBytes(const fs::path& dir, nlohmann::json* sizes = nullptr) {
  uint64_t bytes = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const uint64_t size = entry.file_size();
    bytes += size;
    if (sizes) (*sizes)[entry.path().filename().string()] = size;
  }
  return bytes;
}

// Refuses a build the machine cannot hold, before any work: the octree on disk, the build in memory.
void checkRoom(const PointCloud& cloud, const fs::path& dir, unsigned threads) {
  const uint64_t n = cloud.size();
  std::error_code ec;
  const fs::space_info space = fs::space(dir.parent_path(), ec);
  const uint64_t disk = n * kOctreeBytesPerPoint + kSlackBytes;
  if (!ec && space.available < disk)
    throw InputError(dir.parent_path().string() + ": the octree of " + humanCount(double(n)) +
                     " points needs about " + gb(disk) + " of disk, " + gb(space.available) + " are free");
  const uint64_t chunk = lod::inMemoryChunkLimit(n, threads, io::LodBuildOptions{}.leafPoints);
  const uint64_t memory = n * kBuildBytesPerPoint + threads * chunk * kIndexBytesPerPoint + kSlackBytes;
  if (memory > io::defaultBuildMemory())
    throw InputError("building the octree of " + humanCount(double(n)) + " points in memory needs about " +
                     gb(memory) + ", more than half of this machine's memory (" +
                     gb(io::defaultBuildMemory()) + "); use a smaller --scale");
}

// The cloud as the builder's input: pieces of records, converted in parallel.
lod::Pieces piecesOf(const PointCloud& cloud, unsigned threads) {
  const uint64_t n = cloud.size();
  lod::Pieces pieces((n + kPiecePoints - 1) / kPiecePoints);
  parallelBlocksOn(threads, n, kPiecePoints, [&](uint64_t piece, uint64_t begin, uint64_t end) {
    pieces[piece].resize(end - begin);
    loadRecords(cloud, begin, end - begin, pieces[piece].data());
  });
  return pieces;
}

// A build's partial folder ("KEY.partial-PID", the PotreeWriter's) whose process is gone: a killed run's.
bool abandonedPartial(const fs::path& entry, const std::string& key) {
  const std::string name = entry.filename().string(), prefix = key + ".partial-";
  if (name.rfind(prefix, 0) != 0) return false;
  char* end = nullptr;
  const long pid = std::strtol(name.c_str() + prefix.size(), &end, 10);
  if (pid <= 0 || *end != '\0') return false;
  return ::kill(pid_t(pid), 0) != 0 && errno == ESRCH;
}

class OctreeCache {
public:
  explicit OctreeCache(OctreeCacheOptions options) : o_(std::move(options)) {
    if (!o_.threads) o_.threads = hardwareThreads();
  }

  DatasetOctree get(const std::string& key, const std::function<const PointCloud&()>& points) {
    createDir();
    const fs::path dir = o_.dir / key, record = o_.dir / (key + ".json");
    std::error_code ec;
    if (fs::exists(fs::symlink_status(dir, ec))) {
      std::string damage;
      DatasetOctree o = reuse(key, dir, record, damage);
      if (damage.empty()) return o;
      note("octree cache: " + dir.string() + " is damaged (" + damage + "); building it again");
      remove(dir);
    }
    remove(record);
    removeAbandoned(key);
    return build(key, dir, record, points());
  }

private:
  void note(const std::string& line) const {
    if (o_.onNote) o_.onNote(line);
  }

  void createDir() const {
    std::error_code ec;
    fs::create_directories(o_.dir, ec);
    if (ec || !fs::is_directory(o_.dir, ec))
      throw InputError(o_.dir.string() + ": cannot create the octree cache folder (" + ec.message() + ")");
  }

  static void remove(const fs::path& path) {
    std::error_code ec;
    fs::remove_all(path, ec);
    if (ec)
      throw InputError(path.string() + ": a damaged octree cache entry that cannot be removed (" +
                       ec.message() + ")");
  }

  void removeAbandoned(const std::string& key) const {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(o_.dir, ec))
      if (abandonedPartial(entry.path(), key)) {
        note("octree cache: removing " + entry.path().string() + ", left by a build that was stopped");
        remove(entry.path());
      }
  }

  // The cached entry, or why it cannot be used (in `damage`).
  static DatasetOctree reuse(const std::string& key, const fs::path& dir, const fs::path& record,
                             std::string& damage) {
    DatasetOctree o;
    o.path = dir;
    o.reused = true;
    nlohmann::json j;
    std::ifstream in(record);
    if (!in) {
      damage = "no build record " + record.filename().string();
      return o;
    }
    try {
      j = nlohmann::json::parse(in);
      if (j.at("key").get<std::string>() != key) {
        damage = "its build record names another octree";
        return o;
      }
      nlohmann::json sizes;
      std::error_code ec;
      if (!fs::is_directory(dir, ec)) {
        damage = "not a folder";
        return o;
      }
      o.bytes = folderBytes(dir, &sizes);
      if (sizes != j.at("files")) {
        damage = "its files are not those its build wrote";
        return o;
      }
      o.points = j.at("points").get<uint64_t>();
      o.buildSeconds = j.at("build_seconds").get<double>();
      o.phases = j.at("phases").get<std::string>();
    } catch (const std::exception&) { // nlohmann's parse and type errors, a folder that cannot be listed
      damage = "its build record " + record.filename().string() + " is unreadable";
      return o;
    }
    try {
      if (io::openNodeSource(dir)->metadata().pointCount != o.points)
        damage = "it holds another number of points than its build wrote";
    } catch (const InputError& e) {
      damage = e.what();
    }
    return o;
  }

  DatasetOctree build(const std::string& key, const fs::path& dir, const fs::path& record,
                      const PointCloud& cloud) const {
    checkRoom(cloud, dir, o_.threads);
    note("octree cache: building " + dir.string() + " from " + humanCount(double(cloud.size())) +
         " points on " + std::to_string(o_.threads) + " threads");
    DatasetOctree o = buildCloudOctree(cloud, dir, o_.threads, o_.progress);
    nlohmann::json j;
    j["key"] = key;
    j["points"] = o.points;
    j["build_seconds"] = o.buildSeconds;
    j["phases"] = o.phases;
    j["threads"] = o_.threads;
    j["built"] = utcNow();
    nlohmann::json sizes;
    folderBytes(dir, &sizes);
    j["files"] = sizes;
    writeAtomically(record, jsonFileText(j));
    note("octree cache: built " + dir.string() + " in " + printf1("%.1f s", o.buildSeconds) + " (" +
         o.phases + ")");
    return o;
  }

  OctreeCacheOptions o_;
};

} // namespace

fs::path defaultOctreeCacheDir() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg && *xdg == '/') return fs::path(xdg) / "pointrast" / "octrees";
  const char* home = std::getenv("HOME");
  if (!home || !*home)
    throw InputError("no home folder (HOME is not set) for the octree cache; give --octree-cache DIR");
  return fs::path(home) / ".cache" / "pointrast" / "octrees";
}

OctreeProvider octreeCache(OctreeCacheOptions options) {
  auto cache = std::make_shared<OctreeCache>(std::move(options));
  return [cache](const std::string& key, const std::function<const PointCloud&()>& points) {
    return cache->get(key, points);
  };
}

DatasetOctree buildCloudOctree(const PointCloud& cloud, const fs::path& dir, unsigned threads,
                               bool progress) {
  if (cloud.size() == 0) throw InputError(cloud.source + ": no points to build an octree from");
  const auto start = std::chrono::steady_clock::now();
  lod::LodRunOptions run;
  run.threads = threads ? threads : hardwareThreads();
  run.progress = progress;
  std::vector<lod::LodPhase> phases;

  const lod::PhaseClock recordsClock;
  lod::Pieces pieces = piecesOf(cloud, run.threads);
  const pointrast::detail::QuantBox box = lod::quantBoxOf(pieces, run);
  phases.push_back(recordsClock.done("records", cloud.size()));

  // The frame the builder chooses for files (io::OctreeBuilder::scan): the default root spacing.
  const lod::LodGrid grid = lod::makeLodGrid(box, cloud.scale, cloud.offset);
  lod::OctreeMetadata meta;
  meta.source = cloud.source;
  meta.cube = grid.cube;
  meta.bounds = pointrast::detail::worldBounds(box, grid.scale, grid.offset);
  meta.spacing = grid.spacing();
  meta.scale = grid.scale;
  meta.offset = grid.offset;
  meta.pointCount = cloud.size();
  meta.fields = recordFieldsOf(cloud);

  io::PotreeWriter writer(dir, meta, {});
  io::PotreeNodeSink sink(writer);
  const lod::LodBuildStats stats = lod::buildInMemory(std::move(pieces), grid, lod::LodParams{}, sink, run);
  phases.insert(phases.end(), stats.phases.begin(), stats.phases.end());
  const lod::PhaseClock commitClock;
  writer.commit();
  phases.push_back(commitClock.done("commit", 0));

  DatasetOctree o;
  o.path = dir;
  o.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.points = stats.octree.points;
  o.bytes = folderBytes(dir);
  o.phases = phasesText(phases);
  return o;
}

} // namespace pointrast::bench

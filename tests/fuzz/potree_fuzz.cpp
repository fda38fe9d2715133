// libFuzzer target for the Potree 2.0 reader: one input holds the three files of an octree folder,
//   uint32 n1, n1 bytes of metadata.json, uint32 n2, n2 bytes of hierarchy.bin, the rest octree.bin
// (lengths little endian, clamped to what is there). They are written into a folder of this process, then
// the octree is opened, walked and every node read (the NodeSource), and read whole (readCloud).
// InputError is the expected way to refuse; anything else escapes and is a finding.
//
// Seeds: with POTREE_FUZZ_SEEDS=DIR set, the target first writes small valid octrees in this layout
// into DIR (both encodings, several chunk sizes):
//   POTREE_FUZZ_SEEDS=corpus ./potree_fuzz -runs=0 corpus && ./potree_fuzz -max_total_time=300 corpus
#include <cstdlib>
#include <fstream>
#include <string>

#include <unistd.h>

#include "base/error.h"
#include "base/progress.h"
#include "io/potree/potree.h"
#include "io/reader.h"

namespace {

std::filesystem::path workDir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("pointrast-potree-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

void writeFile(const std::filesystem::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

// The next length-prefixed part of the input.
std::pair<const uint8_t*, size_t> part(const uint8_t*& data, size_t& size) {
  uint32_t n = 0;
  for (int i = 0; i < 4 && size > 0; ++i, ++data, --size)
    n |= uint32_t(*data) << (8 * i);
  const size_t take = std::min<size_t>(n, size);
  const uint8_t* begin = data;
  data += take;
  size -= take;
  return {begin, take};
}

std::string readAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void appendPart(std::string& out, const std::string& bytes) {
  const uint32_t n = uint32_t(bytes.size());
  for (int i = 0; i < 4; ++i)
    out.push_back(char((n >> (8 * i)) & 0xFF));
  out += bytes;
}

// Small octrees of pseudo-random points in the fuzzer's input layout.
void writeSeeds(const std::filesystem::path& dir) {
  using namespace pointrast;
  std::filesystem::create_directories(dir);
  int seed = 0;
  for (io::PotreeEncoding encoding : {io::PotreeEncoding::Default, io::PotreeEncoding::Brotli})
    for (int step : {1, 2, 4}) {
      lod::OctreeMetadata meta;
      meta.cube.min = glm::dvec3(10.0);
      meta.cube.max = glm::dvec3(10.0 + 65.536);
      meta.offset = meta.cube.min;
      meta.scale = glm::dvec3(0.001);
      meta.spacing = 65.536 / 128;
      meta.fields.color = meta.fields.intensity = meta.fields.classification = true;
      meta.fields.returnNumber = meta.fields.pointSourceId = step != 2;
      const auto target = workDir() / "seed";
      std::filesystem::remove_all(target);
      {
        io::PotreeWriteOptions options;
        options.encoding = encoding;
        options.hierarchyStepSize = step;
        io::PotreeWriter writer(target, meta, options);
        uint32_t state = 12345u + uint32_t(seed);
        auto next = [&] { return state = state * 1664525u + 1013904223u; };
        // Root, its children, and a chain down to level 4 below child 3.
        std::vector<lod::NodeKey> keys{lod::NodeKey{}};
        for (int c = 0; c < 8; ++c)
          keys.push_back(lod::NodeKey{}.child(c));
        for (lod::NodeKey k = lod::NodeKey{}.child(3); k.level < 4;)
          keys.push_back(k = k.child(int(next() % 8)));
        for (const lod::NodeKey& key : keys) {
          std::vector<PointRecord> records(1 + next() % 5);
          const int32_t edge = 65536 >> key.level;
          for (PointRecord& r : records) {
            r.x = key.x * edge + int32_t(next() % uint32_t(edge));
            r.y = key.y * edge + int32_t(next() % uint32_t(edge));
            r.z = key.z * edge + int32_t(next() % uint32_t(edge));
            r.rgb[0] = uint16_t(next());
            r.intensity = uint16_t(next());
            r.classification = uint8_t(next() % 10);
          }
          writer.writeNode(key, records.data(), records.size());
        }
        writer.commit();
      }
      std::string input;
      appendPart(input, readAll(target / "metadata.json"));
      appendPart(input, readAll(target / "hierarchy.bin"));
      input += readAll(target / "octree.bin");
      std::ofstream(dir / ("seed" + std::to_string(seed++)), std::ios::binary) << input;
    }
}

} // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  pointrast::Progress::setEnabled(false);
  if (const char* seeds = std::getenv("POTREE_FUZZ_SEEDS"); seeds && *seeds) writeSeeds(seeds);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace pointrast;
  const auto [metadata, metadataSize] = part(data, size);
  const auto [hierarchy, hierarchySize] = part(data, size);
  const std::filesystem::path dir = workDir() / "octree";
  std::filesystem::create_directories(dir);
  writeFile(dir / "metadata.json", metadata, metadataSize);
  writeFile(dir / "hierarchy.bin", hierarchy, hierarchySize);
  writeFile(dir / "octree.bin", data, size);
  try {
    std::unique_ptr<lod::NodeSource> source = io::openPotree(dir);
    lod::forEachNode(*source, [&](const lod::NodeInfo& node) {
      if (source->readNode(node).size() > node.pointCount) __builtin_trap();
      return true;
    });
  } catch (const InputError&) {
  }
  try {
    io::ReadOptions options;
    options.progress = false;
    PointCloud cloud = io::readCloud(dir, options);
    if (cloud.positions.size() != 3 * cloud.size()) __builtin_trap();
  } catch (const InputError&) {
  }
  return 0;
}

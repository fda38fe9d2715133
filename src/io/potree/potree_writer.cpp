// PotreeWriter: octree.bin as nodes arrive, hierarchy.bin and metadata.json at commit(), all in a
// temporary sibling folder renamed into place at the end.
#include <cassert>
#include <cerrno>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_set>

#include <fcntl.h>
#include <unistd.h>

#include "io/io_util.h"
#include "io/potree/potree_format.h"
#include "io/stale_partials.h"
#include "io/write_behind.h"

namespace pointrast::io {

using namespace detail;

void PotreeValueRanges::add(const PointRecord* records, size_t n) {
  potree::RecordExtremes extremes(*this);
  for (size_t i = 0; i < n; ++i)
    extremes.include(records[i]);
  extremes.into(*this);
  count += n;
}

namespace potree {

namespace {

PointRecord recordOf(const std::array<int32_t, 3>& position, const std::array<uint16_t, 3>& rgb,
                     uint16_t intensity, uint8_t returnNumber, uint8_t classification, uint16_t source) {
  PointRecord r;
  r.x = position[0];
  r.y = position[1];
  r.z = position[2];
  for (int c = 0; c < 3; ++c)
    r.rgb[c] = rgb[c];
  r.intensity = intensity;
  r.returnNumber = returnNumber;
  r.classification = classification;
  r.pointSourceId = source;
  return r;
}

} // namespace

RecordExtremes::RecordExtremes(const PotreeValueRanges& s) {
  const PointRecord lo =
      recordOf(s.positionMin, s.rgbMin, s.intensityMin, s.returnMin, s.classMin, s.sourceMin);
  const PointRecord hi =
      recordOf(s.positionMax, s.rgbMax, s.intensityMax, s.returnMax, s.classMax, s.sourceMax);
  const auto* l = reinterpret_cast<const uint8_t*>(&lo);
  const auto* h = reinterpret_cast<const uint8_t*>(&hi);
  std::memcpy(&posMin_, l, 16);
  std::memcpy(&posMax_, h, 16);
  std::memcpy(&u16Min_, l + 8, 16);
  std::memcpy(&u16Max_, h + 8, 16);
  std::memcpy(&u8Min_, l + 8, 16);
  std::memcpy(&u8Max_, h + 8, 16);
}

void RecordExtremes::into(PotreeValueRanges& s) const {
  for (int a = 0; a < 3; ++a) {
    s.positionMin[a] = posMin_[a];
    s.positionMax[a] = posMax_[a];
    s.rgbMin[a] = u16Min_[2 + a];
    s.rgbMax[a] = u16Max_[2 + a];
  }
  s.intensityMin = u16Min_[5];
  s.intensityMax = u16Max_[5];
  s.sourceMin = u16Min_[7];
  s.sourceMax = u16Max_[7];
  s.returnMin = u8Min_[12];
  s.returnMax = u8Max_[12];
  s.classMin = u8Min_[13];
  s.classMax = u8Max_[13];
}

} // namespace potree

void PotreeValueRanges::merge(const PotreeValueRanges& o) {
  for (int a = 0; a < 3; ++a) {
    positionMin[a] = std::min(positionMin[a], o.positionMin[a]);
    positionMax[a] = std::max(positionMax[a], o.positionMax[a]);
    rgbMin[a] = std::min(rgbMin[a], o.rgbMin[a]);
    rgbMax[a] = std::max(rgbMax[a], o.rgbMax[a]);
  }
  intensityMin = std::min(intensityMin, o.intensityMin);
  intensityMax = std::max(intensityMax, o.intensityMax);
  returnMin = std::min(returnMin, o.returnMin);
  returnMax = std::max(returnMax, o.returnMax);
  classMin = std::min(classMin, o.classMin);
  classMax = std::max(classMax, o.classMax);
  sourceMin = std::min(sourceMin, o.sourceMin);
  sourceMax = std::max(sourceMax, o.sourceMax);
  if (tailMin.empty()) {
    tailMin = o.tailMin;
    tailMax = o.tailMax;
  } else {
    for (size_t i = 0; i < o.tailMin.size() && i < tailMin.size(); ++i) {
      tailMin[i] = std::min(tailMin[i], o.tailMin[i]);
      tailMax[i] = std::max(tailMax[i], o.tailMax[i]);
    }
  }
  count += o.count;
}

struct PotreeWriter::State {
  std::filesystem::path dir, work;
  lod::OctreeMetadata metadata;
  PotreeWriteOptions options;
  potree::Layout layout;
  int octree = -1;    // octree.bin, written with pwrite at the offsets place() assigns
  std::unique_ptr<WriteBehind> behind; // octree.bin's dirty pages, bounded
  uint64_t bytes = 0; // placed
  std::vector<potree::WrittenNode> nodes;
  std::unordered_set<lod::NodeKey, lod::NodeKeyHash> written;
  PotreeValueRanges ranges;
  bool committed = false;

  potree::Metadata describe(const potree::HierarchyBytes& hierarchy) const;
  [[noreturn]] void failWrite(int error) const {
    fail(dir, strFormat("cannot write: %s", std::strerror(error)));
  }

  void writeFile(const std::string& name, const void* data, size_t n) const {
    std::FILE* f = std::fopen((work / name).c_str(), "wb");
    if (!f) failWrite(errno);
    errno = 0;
    const bool ok = std::fwrite(data, 1, n, f) == n && std::fflush(f) == 0;
    const int error = errno;
    if (std::fclose(f) != 0 || !ok) failWrite(error ? error : EIO);
  }
};

namespace {

// The folder without a trailing separator ("out/" names "out").
std::filesystem::path normalFolder(std::filesystem::path dir) {
  dir = dir.lexically_normal();
  if (dir.filename().empty() && dir.has_parent_path()) dir = dir.parent_path();
  return dir;
}

void checkMetadata(const std::filesystem::path& dir, const lod::OctreeMetadata& m) {
  for (int a = 0; a < 3; ++a) {
    if (!(std::isfinite(m.scale[a]) && m.scale[a] > 0) || !std::isfinite(m.offset[a]))
      fail(dir, "the octree's scale/offset cannot be written (a scale must be positive and finite)");
    if (!std::isfinite(m.cube.min[a]) || !std::isfinite(m.cube.max[a]) || m.cube.max[a] < m.cube.min[a])
      fail(dir, "the octree's cube is not finite");
  }
  if (!std::isfinite(m.spacing) || m.spacing < 0) fail(dir, "the octree's spacing is not a finite number");
  // Readers (the Potree viewer among them) halve this box into children: it must be the cube
  // OctreeMetadata promises, or nodes would not be where the hierarchy says.
  // Equal up to the rounding of its corners: far from the origin (offsets of 1e12) a double's step
  // there is larger than a billionth of the edge.
  const glm::dvec3 edges = m.cube.max - m.cube.min;
  const double edge = std::max({edges.x, edges.y, edges.z});
  const glm::dvec3 reach = glm::max(glm::abs(m.cube.min), glm::abs(m.cube.max));
  const double tolerance =
      1e-9 * edge + 8 * std::numeric_limits<double>::epsilon() * std::max({reach.x, reach.y, reach.z});
  assert(edge - std::min({edges.x, edges.y, edges.z}) <= tolerance && "the octree's cube has equal edges");
  if (edge - std::min({edges.x, edges.y, edges.z}) > tolerance)
    fail(dir, "the octree's bounding box is not a cube");
}

} // namespace

// metadata.json's attributes with their ranges (those of nothing written: the cube's corner and zeros).
potree::Metadata PotreeWriter::State::describe(const potree::HierarchyBytes& hierarchy) const {
  const State& s = *this;
  potree::Metadata m;
  m.name = s.options.name.empty() ? s.dir.filename().string() : s.options.name;
  m.description = s.options.description;
  m.generator = potree::kGenerator;
  m.encoding = s.options.encoding;
  m.points = s.ranges.count;
  m.offset = s.metadata.offset;
  m.scale = s.metadata.scale;
  m.spacing = s.metadata.spacing;
  m.cube = s.metadata.cube;
  m.firstChunkSize = hierarchy.firstChunkSize;
  m.stepSize = s.options.hierarchyStepSize;
  m.depth = hierarchy.depth;
  m.layout = s.layout;
  const PotreeValueRanges& r = s.ranges;
  const bool any = r.count > 0;
  auto one = [&](double lo, double hi, potree::Attribute& a) {
    a.min = {any ? lo : 0.0};
    a.max = {any ? hi : 0.0};
  };
  for (potree::Attribute& a : m.layout.attributes) {
    switch (a.field) {
    case potree::Field::Position: {
      Bounds b = any ? boundsFromQuantized(r.positionMin.data(), r.positionMax.data(), m.scale, m.offset)
                     : Bounds{m.cube.min, m.cube.min};
      a.min = {b.min.x, b.min.y, b.min.z};
      a.max = {b.max.x, b.max.y, b.max.z};
      break;
    }
    case potree::Field::Rgb:
      for (int c = 0; c < 3; ++c) {
        a.min.push_back(any ? r.rgbMin[c] : 0);
        a.max.push_back(any ? r.rgbMax[c] : 0);
      }
      break;
    case potree::Field::Intensity:
      one(r.intensityMin, r.intensityMax, a);
      break;
    case potree::Field::ReturnNumber:
      one(r.returnMin, r.returnMax, a);
      break;
    case potree::Field::Classification:
      one(r.classMin, r.classMax, a);
      break;
    case potree::Field::PointSourceId:
      one(r.sourceMin, r.sourceMax, a);
      break;
    case potree::Field::Other:
      break;
    }
  }
  // The tail attributes' ranges, element after element (zeros when no point carried one).
  size_t element = 0;
  int at = 0;
  for (potree::Attribute& a : m.layout.attributes) {
    const bool tail = a.field == potree::Field::Other && potree::tailSlotAt(m.layout, at);
    at += a.size;
    if (!tail) continue;
    a.min.clear();
    a.max.clear();
    for (int e = 0; e < a.numElements; ++e, ++element) {
      const bool known = element < r.tailMin.size();
      a.min.push_back(known ? r.tailMin[element] : 0.0);
      a.max.push_back(known ? r.tailMax[element] : 0.0);
    }
  }
  return m;
}

PotreeWriter::PotreeWriter(std::filesystem::path dir, const lod::OctreeMetadata& metadata,
                           const PotreeWriteOptions& options)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.dir = normalFolder(std::move(dir));
  s.metadata = metadata;
  s.options = options;
  assert(options.hierarchyStepSize >= 1 && options.hierarchyStepSize <= potree::kMaxLevel);
  checkMetadata(s.dir, metadata);
  s.layout = potree::writerLayout(metadata.fields, options.tail);
  std::error_code ec;
  if (std::filesystem::exists(std::filesystem::symlink_status(s.dir, ec)))
    fail(s.dir, "already exists (an octree is written into a new folder)");
  // A name of this process: a folder left by a killed build (another pid) never blocks a new one.
  s.work = partialPath(s.dir);
  removeStalePartials(s.dir); // those of killed builds
  std::filesystem::remove_all(s.work, ec);
  if (!std::filesystem::create_directory(s.work, ec))
    fail(s.dir, "cannot create: " + (ec ? ec.message() : std::string("a folder of that name exists")));
  s.octree = ::open((s.work / "octree.bin").c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (s.octree < 0) {
    const int error = errno;
    std::filesystem::remove_all(s.work, ec);
    s.failWrite(error);
  }
  s.behind = std::make_unique<WriteBehind>(s.octree);
}

PotreeWriter::~PotreeWriter() {
  State& s = *state_;
  if (s.committed) return;
  s.behind.reset();
  if (s.octree >= 0) ::close(s.octree);
  std::error_code ignored;
  std::filesystem::remove_all(s.work, ignored);
}

const std::filesystem::path& PotreeWriter::workingDir() const {
  return state_->work;
}

uint64_t PotreeWriter::bytesWritten() const {
  return state_->bytes;
}

PotreeEncodedNode PotreeWriter::encodeNode(const PointRecord* records, size_t count) const {
  return encodeNode(records, nullptr, count);
}

PotreeEncodedNode PotreeWriter::encodeNode(const PointRecord* records, const uint8_t* tails,
                                           size_t count) const {
  const State& s = *state_;
  PotreeEncodedNode node;
  if (s.options.encoding == PotreeEncoding::Brotli) {
    node.ranges.add(records, count);
    node.bytes = potree::encodeBrotli(s.layout, records, s.layout.tailSlots.empty() ? nullptr : tails, count);
  } else {
    node.bytes.resize(count * static_cast<size_t>(s.layout.defaultStride));
    potree::encodeDefault(s.layout, records, count, node.bytes.data(), node.ranges);
    if (tails && !s.layout.tailSlots.empty())
      potree::encodeDefaultTails(s.layout, tails, count, node.bytes.data());
  }
  if (tails && !s.layout.tailSlots.empty()) potree::addTailRanges(s.layout, tails, count, node.ranges);
  return node;
}

void PotreeWriter::writeNode(const lod::NodeKey& key, const PointRecord* records, size_t count) {
  writeEncoded(key, encodeNode(records, count));
}

void PotreeWriter::writeNode(const lod::NodeKey& key, const PointRecord* records, const uint8_t* tails,
                             size_t count) {
  writeEncoded(key, encodeNode(records, tails, count));
}

void PotreeWriter::writeEncoded(const lod::NodeKey& key, const PotreeEncodedNode& node) {
  writeAt(place(key, node), node);
}

uint64_t PotreeWriter::place(const lod::NodeKey& key, const PotreeEncodedNode& node) {
  State& s = *state_;
  assert(!s.committed && s.octree >= 0);
  const bool keyValid = key.level >= 0 && key.level <= potree::kMaxLevel && key.x >= 0 && key.y >= 0 &&
                        key.z >= 0 && int64_t(key.x) >> key.level == 0 && int64_t(key.y) >> key.level == 0 &&
                        int64_t(key.z) >> key.level == 0;
  assert(keyValid && "a node key inside its level's grid");
  if (!keyValid || !s.written.insert(key).second)
    throw std::logic_error("Potree writer: node " + key.potreeName() + " is not a new node of the tree");
  const uint64_t count = node.ranges.count;
  if (count > UINT32_MAX)
    fail(s.dir, strFormat("node %s holds %llu points; a Potree 2.0 node holds at most 4294967295",
                          key.potreeName().c_str(), static_cast<unsigned long long>(count)));
  // Readers refuse a BROTLI node that inflates past brotliDecodedLimit (a lying count looks the same),
  // so such a node is not written: only thousands of identical points compress that far.
  if (s.options.encoding == PotreeEncoding::Brotli &&
      count * s.layout.brotliStride > potree::brotliDecodedLimit(node.bytes.size()))
    fail(s.dir, strFormat("node %s: its %llu points are so alike that Brotli compresses them more than "
                          "4096x, past what readers accept from a node; write the DEFAULT encoding",
                          key.potreeName().c_str(), static_cast<unsigned long long>(count)));
  const uint64_t offset = s.bytes;
  s.nodes.push_back({key, uint32_t(count), offset, node.bytes.size()});
  s.bytes += node.bytes.size();
  s.ranges.merge(node.ranges);
  return offset;
}

void PotreeWriter::writeAt(uint64_t offset, const PotreeEncodedNode& node) const {
  const State& s = *state_;
  assert(!s.committed && s.octree >= 0);
  size_t done = 0;
  while (done < node.bytes.size()) {
    const ssize_t n = ::pwrite(s.octree, node.bytes.data() + done, node.bytes.size() - done,
                               static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) s.failWrite(n < 0 ? errno : EIO);
    done += static_cast<size_t>(n);
  }
  s.behind->written(offset, node.bytes.size());
}

void PotreeWriter::commit() {
  State& s = *state_;
  assert(!s.committed && s.octree >= 0);
  const int flushError = s.behind->finish();
  s.behind.reset();
  if (flushError != 0) s.failWrite(flushError);
  const int closed = ::close(s.octree);
  s.octree = -1;
  if (closed != 0) s.failWrite(errno);

  if (s.nodes.empty()) s.nodes.push_back({lod::NodeKey{}, 0, 0, 0}); // an empty octree is an empty root
  const potree::HierarchyBytes hierarchy = potree::buildHierarchy(s.nodes, s.options.hierarchyStepSize);
  s.writeFile("hierarchy.bin", hierarchy.bytes.data(), hierarchy.bytes.size());
  const std::string json = potree::metadataJson(s.describe(hierarchy));
  s.writeFile("metadata.json", json.data(), json.size());

  std::error_code ec;
  if (std::filesystem::exists(std::filesystem::symlink_status(s.dir, ec)))
    fail(s.dir, "appeared while the octree was written; it was left as it is");
  std::filesystem::rename(s.work, s.dir, ec);
  if (ec) s.failWrite(ec.value());
  s.committed = true;
}

} // namespace pointrast::io

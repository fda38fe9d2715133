// Reading Potree 2.0 octrees: metadata.json up front, hierarchy.bin one chunk at a time as nodes below a
// proxy are asked for, each node's points from octree.bin on their own. Everything a hierarchy record
// claims is checked before it is used: byte ranges lie inside their file and never overlap (so a proxy
// cannot lead back into a chunk already read, and no cycle or repetition can make the tree grow beyond
// the file), DEFAULT nodes occupy exactly count x stride bytes, BROTLI nodes inflate to at most
// brotliDecodedLimit, levels stop at kMaxLevel.
#include <map>
#include <mutex>
#include <stdexcept>
#include <unordered_map>

#include "cloud/lod_tails.h"
#include "io/io_util.h"
#include "io/las/las_tail_values.h"
#include "io/potree/potree_format.h"

namespace pointrast::io {

using namespace detail;

namespace {

constexpr uint64_t kMaxMetadataBytes = uint64_t(16) << 20; // PotreeConverter writes a few KiB

// The octree's folder: the path itself, or the folder of its metadata.json.
std::filesystem::path folderOf(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return path;
  if (path.filename() != "metadata.json")
    fail(path, "not a Potree 2.0 octree (neither its folder nor its metadata.json)");
  std::filesystem::path parent = path.parent_path();
  return parent.empty() ? std::filesystem::path(".") : parent;
}

potree::Metadata readMetadata(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / "metadata.json";
  InputFile file(path);
  if (file.size() > kMaxMetadataBytes)
    fail(path, strFormat("%llu bytes is far too large for an octree's metadata",
                         static_cast<unsigned long long>(file.size())));
  std::string text(static_cast<size_t>(file.size()), '\0');
  file.readAt(0, text.data(), text.size());
  return potree::parseMetadata(text, path);
}

// Byte ranges of one file that records have claimed; a second claim on any byte is refused.
class RangeSet {
public:
  bool claim(uint64_t start, uint64_t size) {
    if (size == 0) return true;
    auto next = used_.lower_bound(start);
    if (next != used_.end() && next->first < start + size) return false;
    if (next != used_.begin() && std::prev(next)->second > start) return false;
    used_.emplace(start, start + size);
    return true;
  }

private:
  std::map<uint64_t, uint64_t> used_; // start -> end
};

class PotreeSource final : public lod::NodeSource, public lod::NodeTails {
public:
  explicit PotreeSource(const std::filesystem::path& path);

  const lod::OctreeMetadata& metadata() const override { return info_; }
  lod::NodeInfo root() override;
  std::vector<lod::NodeInfo> children(const lod::NodeInfo& node) override;
  std::vector<PointRecord> readNode(const lod::NodeInfo& node) override;
  const TailFormat& tailFormat() const override { return meta_.layout.tail; }
  std::vector<PointRecord> readNodeTails(const lod::NodeInfo& node, std::vector<uint8_t>& tails) override;
  std::vector<lod::TailValue> tailValues(const uint8_t* tail) const override { return tailValues_(tail); }
  uint64_t nodeBytes(const lod::NodeInfo& node) override;

private:
  struct Node {
    uint32_t count = 0;
    uint8_t mask = 0;
    bool proxy = false; // offset/size locate the node's hierarchy chunk, not yet read
    uint64_t offset = 0, size = 0;
    std::string damage; // why its chunk could not be read (said again on every later request)
  };

  std::vector<PointRecord> read(const lod::NodeInfo& node, std::vector<uint8_t>* tails);

  // All below: mutex_ held.
  Node& find(const lod::NodeKey& key);
  Node& resolved(const lod::NodeKey& key);
  void loadChunk(const lod::NodeKey& root, int64_t offset, int64_t size);
  Node checkedNode(const lod::NodeKey& key, const potree::Record& record);
  lod::NodeInfo info(const lod::NodeKey& key, Node& node);
  [[noreturn]] void failNode(const lod::NodeKey& key, const std::string& what) const {
    fail(hierarchyPath_, "node " + key.potreeName() + " " + what);
  }

  std::filesystem::path dir_, hierarchyPath_, octreePath_;
  potree::Metadata meta_;
  TailValues tailValues_;
  InputFile hierarchy_, octree_;
  lod::OctreeMetadata info_;
  int32_t positionBias_ = 0;
  std::mutex mutex_;
  std::unordered_map<lod::NodeKey, Node, lod::NodeKeyHash> nodes_;
  RangeSet chunkRanges_, pointRanges_;
};

PotreeSource::PotreeSource(const std::filesystem::path& path)
    : dir_(folderOf(path)), hierarchyPath_(dir_ / "hierarchy.bin"), octreePath_(dir_ / "octree.bin"),
      meta_(readMetadata(dir_)), tailValues_(meta_.layout.tail), hierarchy_(hierarchyPath_),
      octree_(octreePath_) {
  info_.source = dir_.string();
  info_.format = std::string("Potree 2.0 (") + potree::encodingName(meta_.encoding) + ")";
  info_.cube = meta_.cube;
  info_.bounds = meta_.bounds.empty() ? meta_.cube : meta_.bounds;
  info_.spacing = meta_.spacing;
  info_.scale = meta_.scale;
  info_.offset = meta_.offset;
  info_.pointCount = meta_.points;
  info_.fields = meta_.layout.fields;
  info_.depth = meta_.depth;
  // PotreeConverter's BROTLI writer stores q + 1 (potree.h); its DEFAULT writer stores q.
  positionBias_ = !meta_.fromPointrast() && meta_.encoding == PotreeEncoding::Brotli ? 1 : 0;
  if (meta_.firstChunkSize > hierarchy_.size())
    fail(hierarchyPath_, strFormat("holds %llu bytes, fewer than the first chunk's %llu that metadata.json "
                                   "states (truncated)",
                                   static_cast<unsigned long long>(hierarchy_.size()),
                                   static_cast<unsigned long long>(meta_.firstChunkSize)));
  std::lock_guard lock(mutex_);
  loadChunk(lod::NodeKey{}, 0, int64_t(meta_.firstChunkSize));
}

PotreeSource::Node& PotreeSource::find(const lod::NodeKey& key) {
  auto it = nodes_.find(key);
  if (it == nodes_.end())
    throw std::logic_error("Potree source: node " + key.potreeName() + " was not listed by this source");
  return it->second;
}

PotreeSource::Node& PotreeSource::resolved(const lod::NodeKey& key) {
  Node& node = find(key);
  if (!node.damage.empty()) throw InputError(node.damage);
  if (!node.proxy) return node;
  try {
    loadChunk(key, int64_t(node.offset), int64_t(node.size));
  } catch (const InputError& e) {
    // Part of the chunk may have been taken in; the proxy stays unresolved and keeps the reason, so a
    // later request gets the same sentence rather than a confusing one about the half-read chunk.
    find(key).damage = e.what();
    throw;
  }
  return find(key); // the map may have rehashed
}

// A non-proxy record's claims, checked against octree.bin and the encoding.
PotreeSource::Node PotreeSource::checkedNode(const lod::NodeKey& key, const potree::Record& record) {
  Node node;
  node.count = record.pointCount;
  node.mask = record.childMask;
  const uint64_t fileSize = octree_.size();
  if (record.byteOffset < 0 || record.byteSize < 0 || uint64_t(record.byteSize) > fileSize ||
      uint64_t(record.byteOffset) > fileSize - uint64_t(record.byteSize))
    failNode(key,
             strFormat("claims %lld bytes at byte %lld of octree.bin, which holds %llu",
                       static_cast<long long>(record.byteSize), static_cast<long long>(record.byteOffset),
                       static_cast<unsigned long long>(fileSize)));
  node.offset = uint64_t(record.byteOffset);
  node.size = uint64_t(record.byteSize);
  // A record that claims points delivers them or is damage, whoever wrote it: reading one without bytes
  // as empty (as Potree's viewer does) would drop its points from a conversion without a word.
  const uint64_t count = node.count;
  if (meta_.encoding == PotreeEncoding::Default) {
    if (count * meta_.layout.defaultStride != node.size)
      failNode(key, strFormat("claims %llu points of %llu bytes but occupies %llu bytes",
                              static_cast<unsigned long long>(count),
                              static_cast<unsigned long long>(meta_.layout.defaultStride),
                              static_cast<unsigned long long>(node.size)));
  } else if (count > 0) {
    if (node.size == 0)
      failNode(key,
               strFormat("claims %llu points but occupies no bytes", static_cast<unsigned long long>(count)));
    if (count * meta_.layout.brotliStride > potree::brotliDecodedLimit(node.size))
      failNode(key,
               strFormat("claims %llu points, more than its %llu bytes of Brotli data can hold",
                         static_cast<unsigned long long>(count), static_cast<unsigned long long>(node.size)));
  }
  if (!pointRanges_.claim(node.offset, node.size))
    failNode(key, strFormat("claims bytes %llu..%llu of octree.bin, which another node claims too",
                            static_cast<unsigned long long>(node.offset),
                            static_cast<unsigned long long>(node.offset + node.size)));
  return node;
}

void PotreeSource::loadChunk(const lod::NodeKey& root, int64_t offset, int64_t size) {
  const uint64_t fileSize = hierarchy_.size();
  if (offset < 0 || size <= 0 || uint64_t(size) > fileSize || uint64_t(offset) > fileSize - uint64_t(size))
    failNode(root, strFormat("points to a hierarchy chunk of %lld bytes at byte %lld, outside the %llu bytes "
                             "of hierarchy.bin",
                             static_cast<long long>(size), static_cast<long long>(offset),
                             static_cast<unsigned long long>(fileSize)));
  if (!chunkRanges_.claim(uint64_t(offset), uint64_t(size)))
    failNode(
        root,
        strFormat("points to a hierarchy chunk of %lld bytes at byte %lld, which overlaps a chunk already "
                  "read (a proxy leading back into the hierarchy: a cycle)",
                  static_cast<long long>(size), static_cast<long long>(offset)));
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  hierarchy_.readAt(uint64_t(offset), bytes.data(), bytes.size());
  const std::vector<potree::ChunkNode> records =
      potree::parseChunk(bytes.data(), bytes.size(), root, hierarchyPath_.string());

  for (size_t i = 0; i < records.size(); ++i) {
    const lod::NodeKey& key = records[i].key;
    const potree::Record& r = records[i].record;
    Node node;
    if (r.type == potree::kProxy) {
      node.count = r.pointCount;
      node.mask = r.childMask;
      node.proxy = true;
      node.offset = uint64_t(r.byteOffset); // checked when the chunk is read
      node.size = uint64_t(r.byteSize);
    } else {
      node = checkedNode(key, r);
    }
    auto existing = nodes_.find(key);
    if (i == 0 && existing != nodes_.end()) {
      // The proxy this chunk stands for: both records describe one node.
      const Node& proxy = existing->second;
      if (r.pointCount != proxy.count || (proxy.mask != 0 && r.childMask != proxy.mask))
        failNode(key, strFormat("is described twice, differently (%u points and child mask %02x in its proxy "
                                "record, %u and %02x in its chunk)",
                                proxy.count, proxy.mask, r.pointCount, r.childMask));
      existing->second = node;
    } else if (existing != nodes_.end()) {
      failNode(key, "appears twice in the hierarchy");
    } else {
      nodes_.emplace(key, node);
    }
  }
}

lod::NodeInfo PotreeSource::info(const lod::NodeKey& key, Node& node) {
  // PotreeConverter's out-of-core hierarchy may leave a proxy's child mask 0; its chunk tells.
  if (node.proxy && node.mask == 0) return info(key, resolved(key));
  return {key, node.count, node.mask};
}

lod::NodeInfo PotreeSource::root() {
  std::lock_guard lock(mutex_);
  return info(lod::NodeKey{}, find(lod::NodeKey{}));
}

std::vector<lod::NodeInfo> PotreeSource::children(const lod::NodeInfo& parent) {
  std::lock_guard lock(mutex_);
  const uint8_t mask = resolved(parent.key).mask;
  std::vector<lod::NodeInfo> out;
  for (int child = 0; child < 8; ++child) {
    if (!(mask & (1u << child))) continue;
    const lod::NodeKey key = parent.key.child(child);
    out.push_back(info(key, find(key)));
  }
  return out;
}

uint64_t PotreeSource::nodeBytes(const lod::NodeInfo& node) {
  std::lock_guard lock(mutex_);
  return resolved(node.key).size;
}

std::vector<PointRecord> PotreeSource::readNode(const lod::NodeInfo& node) {
  return read(node, nullptr);
}

std::vector<PointRecord> PotreeSource::readNodeTails(const lod::NodeInfo& node, std::vector<uint8_t>& tails) {
  tails.clear();
  return read(node, &tails);
}

std::vector<PointRecord> PotreeSource::read(const lod::NodeInfo& node, std::vector<uint8_t>* tails) {
  Node n;
  {
    std::lock_guard lock(mutex_);
    n = resolved(node.key);
  }
  std::vector<PointRecord> out(n.count);
  if (n.count == 0) return out;
  std::vector<uint8_t> bytes(static_cast<size_t>(n.size));
  octree_.readAt(n.offset, bytes.data(), bytes.size());
  if (meta_.encoding == PotreeEncoding::Default) {
    potree::decodeDefault(meta_.layout, bytes.data(), n.count, out.data());
    if (tails && !meta_.layout.tailSlots.empty()) {
      tails->resize(size_t(n.count) * meta_.layout.tail.bytes());
      potree::decodeDefaultTails(meta_.layout, bytes.data(), n.count, tails->data());
    }
  } else {
    const bool withTails = tails && !meta_.layout.tailSlots.empty();
    if (withTails) tails->resize(size_t(n.count) * meta_.layout.tail.bytes());
    potree::decodeBrotli(meta_.layout, bytes.data(), bytes.size(), n.count, positionBias_, out.data(),
                         octreePath_.string() + ": node " + node.key.potreeName(),
                         withTails ? tails->data() : nullptr);
  }
  return out;
}

} // namespace

std::unique_ptr<lod::NodeSource> openPotree(const std::filesystem::path& path) {
  return std::make_unique<PotreeSource>(path);
}

bool looksLikePotree(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return std::filesystem::exists(path / "metadata.json", ec);
  return path.filename() == "metadata.json" && std::filesystem::is_regular_file(path, ec);
}

PotreeFolderInfo probePotree(const std::filesystem::path& path) {
  const potree::Metadata m = readMetadata(folderOf(path));
  PotreeFolderInfo info;
  info.name = m.name;
  info.description = m.description;
  info.projection = m.projection;
  info.encoding = potree::encodingName(m.encoding);
  info.generator = m.generator;
  info.fromPointrast = m.fromPointrast();
  info.stepSize = m.stepSize;
  info.depth = m.depth;
  info.firstChunkSize = m.firstChunkSize;
  for (const potree::Attribute& a : m.layout.attributes)
    info.attributes.push_back({a.name, a.type, a.size, a.numElements, a.min, a.max});
  return info;
}

} // namespace pointrast::io

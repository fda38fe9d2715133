// COPC reader: the LAZ container (laz_format) plus the copc info VLR and hierarchy pages. Pages are
// loaded under a lock when a node below them is first needed; node chunks decode outside it on pooled
// decoders, so streaming workers read nodes in parallel.
#include "io/copc_ept/copc.h"

#include <mutex>
#include <set>
#include <unordered_map>

#include "cloud/lod_tails.h"
#include "io/io_util.h"
#include "io/las/las_attributes.h"
#include "io/las/las_records.h"
#include "io/las/las_tail_values.h"
#include "io/las/laz_reader.h"

namespace pointrast::io {

using namespace detail;
using lod::NodeInfo;
using lod::NodeKey;

namespace {

// COPC 1.0 info VLR (user "copc", record 1, 160 bytes): center x, y, z, half size, spacing (doubles),
// root hierarchy page offset and size (u64), GPS time range (doubles), 11 reserved u64.
constexpr size_t kInfoBytes = 160;
// A hierarchy entry: voxel key (level, x, y, z as int32), offset u64, byte size int32, point count
// int32 (-1: the entry points to the hierarchy page of the key's subtree).
constexpr size_t kEntryBytes = 32;
// Levels beyond this would overflow the int32 cell coordinates; real trees are under 20 deep.
constexpr int32_t kMaxLevel = 30;

struct CopcInfo {
  glm::dvec3 center{0.0};
  double halfSize = 0, spacing = 0;
  uint64_t rootOffset = 0, rootSize = 0;
};

struct Entry {
  uint64_t offset = 0;
  int32_t byteSize = 0;
  int32_t pointCount = 0; // -1: a page reference
  bool isPage() const { return pointCount < 0; }
};

std::string keyName(const NodeKey& k) {
  return strFormat("%d-%d-%d-%d", k.level, k.x, k.y, k.z);
}

const LasVlr* findInfoVlr(const LasHeader& hd) {
  for (const LasVlr& vlr : hd.vlrs)
    if (vlr.userId == "copc" && vlr.recordId == 1) return &vlr;
  return nullptr;
}

void checkPageExtent(const InputFile& file, uint64_t offset, uint64_t size, const char* what) {
  if (size == 0 || size % kEntryBytes != 0)
    fail(file.path(), strFormat("COPC %s has %llu bytes, not a multiple of the %zu-byte entries", what,
                                static_cast<unsigned long long>(size), kEntryBytes));
  if (offset > file.size() || size > file.size() - offset)
    fail(file.path(),
         strFormat("COPC %s (%llu bytes at offset %llu) lies outside the file", what,
                   static_cast<unsigned long long>(size), static_cast<unsigned long long>(offset)));
}

CopcInfo readInfo(const InputFile& file, const LasHeader& hd) {
  const std::filesystem::path& path = file.path();
  const LasVlr* vlr = findInfoVlr(hd);
  if (!vlr) fail(path, "not a COPC file (no \"copc\" info VLR)");
  if (vlr->length < kInfoBytes)
    fail(path, strFormat("the COPC info VLR holds %u bytes, fewer than %zu", vlr->length, kInfoBytes));
  uint8_t b[kInfoBytes];
  file.readAt(vlr->dataOffset, b, sizeof b);
  CopcInfo info;
  info.center = {loadLE<double>(b), loadLE<double>(b + 8), loadLE<double>(b + 16)};
  info.halfSize = loadLE<double>(b + 24);
  info.spacing = loadLE<double>(b + 32);
  info.rootOffset = loadLE<uint64_t>(b + 40);
  info.rootSize = loadLE<uint64_t>(b + 48);
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(info.center[a])) fail(path, "the COPC root cube's center is not a finite number");
  if (!(info.halfSize > 0) || !std::isfinite(info.halfSize))
    fail(path, strFormat("the COPC root cube's half size %g is not a positive number", info.halfSize));
  if (!(info.spacing >= 0) || !std::isfinite(info.spacing))
    fail(path, strFormat("the COPC spacing %g is not a number of 0 or more", info.spacing));
  checkPageExtent(file, info.rootOffset, info.rootSize, "root hierarchy page");
  return info;
}

// A COPC node's records are LAS records: their tails (GPS time, returns, flags, scan angle, NIR, extra
// bytes) come with them (cloud/lod_tails.h).
class CopcSource : public lod::NodeSource, public lod::NodeTails {
public:
  explicit CopcSource(const std::filesystem::path& path)
      : file_(path), laz_(laz::openLaz(file_)), pool_(laz_.layout), tail_(lasTailFormat(file_, laz_.header)),
        tailValues_(tail_) {
    const LasHeader& hd = laz_.header;
    info_ = readInfo(file_, hd);
    if (!laz_.layout.layered())
      fail(path, "a COPC file needs layered LAZ chunks (point formats 6-8), this one is pointwise");
    meta_.source = path.filename().string();
    meta_.format = "COPC 1.0";
    meta_.cube.min = info_.center - glm::dvec3(info_.halfSize);
    meta_.cube.max = info_.center + glm::dvec3(info_.halfSize);
    meta_.bounds = hd.bounds;
    meta_.spacing = info_.spacing;
    meta_.scale = hd.scale;
    meta_.offset = hd.offset;
    meta_.pointCount = hd.pointCount;
    meta_.fields = lasRecordFields(hd.hasColor());
    loadPage(NodeKey{}, info_.rootOffset, info_.rootSize);
    const auto root = entries_.find(NodeKey{});
    if (root == entries_.end() || root->second.isPage())
      fail(path, "the COPC root hierarchy page does not list the root node 0-0-0-0");
  }

  const lod::OctreeMetadata& metadata() const override { return meta_; }

  NodeInfo root() override {
    std::lock_guard lock(mutex_);
    return infoOf(NodeKey{});
  }

  std::vector<NodeInfo> children(const NodeInfo& node) override {
    std::lock_guard lock(mutex_);
    std::vector<NodeInfo> out;
    for (int i = 0; i < 8; ++i) {
      const NodeKey key = node.key.child(i);
      auto it = entries_.find(key);
      if (it == entries_.end()) continue;
      if (it->second.isPage()) {
        const Entry page = it->second;
        loadPage(key, page.offset, uint64_t(page.byteSize));
        it = entries_.find(key);
        if (it->second.isPage())
          fail(file_.path(), strFormat("the COPC hierarchy page for node %s does not list that node",
                                       keyName(key).c_str()));
      }
      out.push_back(infoOf(key));
    }
    return out;
  }

  std::vector<PointRecord> readNode(const NodeInfo& node) override { return read(node, nullptr); }

  const TailFormat& tailFormat() const override { return tail_; }
  std::vector<PointRecord> readNodeTails(const NodeInfo& node, std::vector<uint8_t>& tails) override {
    tails.clear();
    return read(node, &tails);
  }
  std::vector<lod::TailValue> tailValues(const uint8_t* tail) const override { return tailValues_(tail); }

  uint64_t nodeBytes(const NodeInfo& node) override { return uint64_t(dataEntry(node.key).byteSize); }

  const CopcInfo& copcInfo() const { return info_; }
  const std::string& software() const { return laz_.header.software; }
  size_t pagesLoaded() {
    std::lock_guard lock(mutex_);
    return pages_.size();
  }

private:
  std::vector<PointRecord> read(const NodeInfo& node, std::vector<uint8_t>* tails) {
    const Entry entry = dataEntry(node.key);
    std::vector<PointRecord> out;
    if (entry.pointCount == 0) return out;
    const LasHeader& hd = laz_.header;
    const laz::Chunk chunk{entry.offset, uint64_t(entry.byteSize), 0, uint64_t(entry.pointCount)};
    std::vector<uint8_t> records;
    pool_.decode(file_, chunk, "COPC node " + keyName(node.key), records);
    const bool extended = las::isExtended(hd.pointFormat);
    const int rgbOffset = hd.rgbOffset();
    out.resize(chunk.pointCount);
    for (size_t k = 0; k < out.size(); ++k)
      out[k] = toPointRecord(records.data() + k * hd.recordLength, extended, rgbOffset);
    if (tails && tail_.bytes() > 0) {
      tails->resize(out.size() * tail_.bytes());
      packLasTails(records.data(), hd.recordLength, out.size(), hd.pointFormat, tail_.attributes.extraBytes,
                   tail_, tails->data());
    }
    return out;
  }

  Entry dataEntry(const NodeKey& key) {
    std::lock_guard lock(mutex_);
    auto it = entries_.find(key);
    if (it == entries_.end() || it->second.isPage())
      fail(file_.path(), strFormat("COPC node %s is not in the hierarchy read so far", keyName(key).c_str()));
    return it->second;
  }

  // The node as the hierarchy lists it; a child counts when any entry names it (its data, or the page of
  // its subtree).
  NodeInfo infoOf(const NodeKey& key) const {
    NodeInfo info;
    info.key = key;
    info.pointCount = uint64_t(entries_.at(key).pointCount);
    for (int i = 0; i < 8; ++i)
      if (key.level < kMaxLevel && entries_.count(key.child(i))) info.childMask |= uint8_t(1u << i);
    return info;
  }

  // Reads the page listing the subtree of pageKey. Every page is read at most once: a second reference
  // to the same bytes is a cycle.
  void loadPage(const NodeKey& pageKey, uint64_t offset, uint64_t size) {
    const std::filesystem::path& path = file_.path();
    checkPageExtent(file_, offset, size,
                    strFormat("hierarchy page of node %s", keyName(pageKey).c_str()).c_str());
    if (!pages_.insert(offset).second)
      fail(path, strFormat("the COPC hierarchy page at offset %llu is referenced twice (a cycle)",
                           static_cast<unsigned long long>(offset)));
    std::vector<uint8_t> bytes(size);
    file_.readAt(offset, bytes.data(), bytes.size());
    const uint64_t chunksStart = uint64_t(laz_.header.pointOffset) + 8;
    for (size_t at = 0; at < bytes.size(); at += kEntryBytes) {
      const uint8_t* e = bytes.data() + at;
      const NodeKey key{loadLE<int32_t>(e), loadLE<int32_t>(e + 4), loadLE<int32_t>(e + 8),
                        loadLE<int32_t>(e + 12)};
      const Entry entry{loadLE<uint64_t>(e + 16), loadLE<int32_t>(e + 24), loadLE<int32_t>(e + 28)};
      const std::string name = keyName(key);
      if (key.level < 0 || key.level > kMaxLevel)
        fail(path, strFormat("COPC hierarchy entry %s has level %d, outside 0..%d", name.c_str(), key.level,
                             kMaxLevel));
      const int32_t cells = int32_t(1) << key.level;
      if (key.x < 0 || key.y < 0 || key.z < 0 || key.x >= cells || key.y >= cells || key.z >= cells)
        fail(path, strFormat("COPC hierarchy entry %s lies outside its level's %d cells per axis",
                             name.c_str(), cells));
      const int32_t up = key.level - pageKey.level;
      if (up < 0 || (key.x >> up) != pageKey.x || (key.y >> up) != pageKey.y || (key.z >> up) != pageKey.z)
        fail(path, strFormat("the COPC hierarchy page of node %s lists node %s, outside its subtree",
                             keyName(pageKey).c_str(), name.c_str()));
      if (entry.pointCount < -1)
        fail(path, strFormat("COPC node %s has a point count of %d", name.c_str(), entry.pointCount));
      if (entry.isPage()) {
        checkPageExtent(file_, entry.offset, uint64_t(std::max(entry.byteSize, 0)),
                        strFormat("hierarchy page of node %s", name.c_str()).c_str());
      } else if (entry.pointCount > 0) {
        if (entry.byteSize <= 0 || entry.offset < chunksStart ||
            uint64_t(entry.byteSize) > laz_.chunkTableOffset - std::min(entry.offset, laz_.chunkTableOffset))
          fail(path, strFormat("COPC node %s (%d bytes at offset %llu) lies outside the point data",
                               name.c_str(), entry.byteSize, static_cast<unsigned long long>(entry.offset)));
      }
      auto [it, added] = entries_.emplace(key, entry);
      if (!added) {
        // A page resolves the reference its parent page made to it; any other repeat is a conflict.
        if (!(it->second.isPage() && key == pageKey && !entry.isPage()))
          fail(path, strFormat("COPC node %s is listed twice in the hierarchy", name.c_str()));
        it->second = entry;
      }
    }
  }

  InputFile file_;
  laz::LazFile laz_;
  ChunkDecoderPool pool_;
  TailFormat tail_;
  TailValues tailValues_;
  CopcInfo info_;
  lod::OctreeMetadata meta_;
  std::mutex mutex_;
  std::unordered_map<NodeKey, Entry, lod::NodeKeyHash> entries_;
  std::set<uint64_t> pages_;
};

} // namespace

std::unique_ptr<lod::NodeSource> openCopc(const std::filesystem::path& path) {
  return std::make_unique<CopcSource>(path);
}

bool hasCopcInfoVlr(const InputFile& file) {
  try {
    return findInfoVlr(readLasHeader(file, true)) != nullptr;
  } catch (const InputError&) {
    return false;
  }
}

bool looksLikeCopc(const std::filesystem::path& path) {
  try {
    return hasCopcInfoVlr(InputFile(path));
  } catch (const InputError&) {
    return false;
  }
}

std::optional<CopcSummary> summarizeCopc(const std::filesystem::path& path) {
  if (!looksLikeCopc(path)) return std::nullopt;
  CopcSource source(path);
  CopcSummary s;
  const CopcInfo& info = source.copcInfo();
  s.center = info.center;
  s.halfSize = info.halfSize;
  s.spacing = info.spacing;
  s.rootPageOffset = info.rootOffset;
  s.rootPageSize = info.rootSize;
  const std::string& software = source.software();
  if (software == kCopcSoftwareAveraged)
    s.colors = "inner nodes hold averaged colors (each point the mean of the points it stands for)";
  else if (software == kCopcSoftwareExact)
    s.colors = "every point keeps its own color";
  lod::forEachNode(source, [&](const NodeInfo& node) {
    ++s.nodes;
    s.points += node.pointCount;
    s.depth = std::max(s.depth, node.key.level);
    return true;
  });
  s.pages = source.pagesLoaded();
  return s;
}

} // namespace pointrast::io

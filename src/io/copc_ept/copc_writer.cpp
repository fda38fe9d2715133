#include "io/copc_ept/copc_writer.h"

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>

#include <fcntl.h>
#include <unistd.h>

#include "io/copc_ept/copc.h"
#include "io/io_util.h"
#include "io/las/las_attributes.h"
#include "io/las/las_format.h"
#include "io/las/laz_encoder.h"
#include "io/stale_partials.h"

namespace pointrast::io {

using namespace detail;
using lod::NodeKey;

namespace {

constexpr size_t kInfoBytes = 160; // the info VLR's payload
constexpr size_t kEntryBytes = 32; // a hierarchy entry: key 4 x int32, offset u64, size int32, count int32
constexpr size_t kEvlrHeaderSize = 60; // R15 section 2.7, Table 26
constexpr uint16_t kWktRecord = 2112;  // "LASF_Projection": OGC coordinate system WKT
constexpr uint16_t kGeoKeysRecord = 34735;

struct Entry {
  uint64_t offset = 0;
  int32_t byteSize = 0;
  int32_t pointCount = 0; // -1: a reference to the key's own page
};

void storeEntry(std::vector<uint8_t>& page, const NodeKey& key, const Entry& e) {
  uint8_t b[kEntryBytes];
  storeLE<int32_t>(b, key.level);
  storeLE<int32_t>(b + 4, key.x);
  storeLE<int32_t>(b + 8, key.y);
  storeLE<int32_t>(b + 12, key.z);
  storeLE<uint64_t>(b + 16, e.offset);
  storeLE<int32_t>(b + 24, e.byteSize);
  storeLE<int32_t>(b + 28, e.pointCount);
  page.insert(page.end(), b, b + kEntryBytes);
}

struct Prepared final : lod::PreparedNode {
  CopcWriter::EncodedNode node;
  uint64_t turn = 0;
  bool reserved = false;
};

} // namespace

struct CopcWriter::State {
  std::filesystem::path path, work, file; // the target, the temporary folder, the file in it
  lod::OctreeMetadata metadata;
  CopcWriteOptions options;
  bool averagedColors = true;
  int pointFormat = 6;
  uint16_t recordLength = 30;
  laz::Layout layout;
  std::vector<uint8_t> prefix; // header and VLRs, rewritten at commit
  uint64_t pointOffset = 0;
  uint64_t next = 0; // where the next chunk with an offset goes
  int fd = -1;
  bool committed = false;
  uint64_t fileBytes = 0;
  // Placed nodes, in file order (the chunk table's order).
  std::vector<std::pair<NodeKey, Entry>> nodes;
  uint64_t count = 0;
  int32_t qmin[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, qmax[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  std::array<uint64_t, 15> byReturn{};
  double gpsMin = 0, gpsMax = 0;
  bool anyGps = false;
  // Turns from the first without an offset (turn firstTurn) on: their nodes once filled.
  struct Turn {
    NodeKey key;
    EncodedNode node;
    bool filled = false;
  };
  std::mutex turnsMutex;
  std::deque<Turn> turns;
  uint64_t firstTurn = 0;
  // Nodes given to writeNode() that wait to be encoded, each with its turn.
  struct Waiting {
    NodeKey key;
    uint64_t turn = 0;
    std::vector<PointRecord> records;
    std::vector<uint8_t> tails;
  };
  std::mutex waitingMutex;
  std::deque<Waiting> waiting;
  // Encoders for the threads that encode at once; each keeps its models from chunk to chunk.
  mutable std::mutex encodersMutex;
  mutable std::vector<std::unique_ptr<laz::ChunkEncoder>> encoders;

  [[noreturn]] void failWrite(int error) const {
    fail(path, strFormat("cannot write: %s", std::strerror(error)));
  }
  void pwriteAll(uint64_t offset, const uint8_t* data, size_t n) const {
    for (size_t done = 0; done < n;) {
      const ssize_t w = ::pwrite(fd, data + done, n - done, static_cast<off_t>(offset + done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) failWrite(w < 0 ? errno : EIO);
      done += static_cast<size_t>(w);
    }
  }
  void place(const NodeKey& key, const EncodedNode& node, uint64_t offset);
  void header();
  void records(const PointRecord* in, const uint8_t* tails, size_t n, std::vector<uint8_t>& out) const;
  std::vector<uint8_t> hierarchy(uint64_t dataOffset, uint64_t& rootOffset, uint64_t& rootSize) const;
};

// Public header block, R15 Table 3. Counts, bounds and offsets are filled in at commit.
void CopcWriter::State::header() {
  prefix.assign(las::kHeaderSize14, 0);
  uint8_t* h = prefix.data();
  std::memcpy(h, "LASF", 4);
  // Bit 4: the coordinate system (if any) is WKT, which point formats 6-10 require (R15 2.4).
  storeLE<uint16_t>(h + las::kGlobalEncoding, 0x10);
  h[las::kVersionMajor] = 1;
  h[las::kVersionMinor] = 4;
  las::copyString(h + las::kSystemId, 32, "pointrast");
  // The creation day and year stay 0 (unknown): the file's bytes depend on its points only.
  las::copyString(h + las::kSoftware, 32,
                  metadata.fields.color && averagedColors ? kCopcSoftwareAveraged : kCopcSoftwareExact);
  storeLE<uint16_t>(h + las::kHeaderSizeField, static_cast<uint16_t>(las::kHeaderSize14));
  for (int a = 0; a < 3; ++a) {
    storeLE<double>(h + las::kScale + 8 * a, metadata.scale[a]);
    storeLE<double>(h + las::kOffset + 8 * a, metadata.offset[a]);
  }
  h[las::kPointFormat] = static_cast<uint8_t>(pointFormat | 0x80); // bit 7: LASzip-compressed
  storeLE<uint16_t>(h + las::kRecordLength, recordLength);
}

// Point formats 6 and 7 (R15 section 2.6, Tables 7 and 8): X, Y, Z int32 at 0; intensity at 12; return
// number and number of returns in byte 14 (4 bits each; the records keep no number of returns, so it is
// written equal to the return number, which keeps the record valid); classification at 16; point source
// id at 20; GPS time (0) at 22; RGB at 30 (format 7).
// With tails, their attributes then fill the rest of each record (las_attributes.h).
void CopcWriter::State::records(const PointRecord* in, const uint8_t* tails, size_t n,
                                std::vector<uint8_t>& out) const {
  const TailFormat& tail = options.tail;
  const int rgbOffset = las::kRgbOffset[size_t(pointFormat)];
  const RecordFields& f = metadata.fields;
  out.assign(n * recordLength, 0);
  for (size_t k = 0; k < n; ++k) {
    const PointRecord& p = in[k];
    uint8_t* r = out.data() + k * recordLength;
    storeLE<int32_t>(r, p.x);
    storeLE<int32_t>(r + 4, p.y);
    storeLE<int32_t>(r + 8, p.z);
    storeLE<uint16_t>(r + 12, f.intensity ? p.intensity : 0);
    const uint8_t rn = (f.returnNumber ? p.returnNumber : 1) & 0x0F;
    r[14] = static_cast<uint8_t>(rn | (rn << 4));
    r[16] = f.classification ? p.classification : 0;
    storeLE<uint16_t>(r + 20, f.pointSourceId ? p.pointSourceId : 0);
    if (rgbOffset >= 0)
      for (int c = 0; c < 3; ++c)
        storeLE<uint16_t>(r + rgbOffset + 2 * c, p.rgb[c]);
    if (tails) unpackLasAttributes(tails + k * tail.bytes(), tail.layout, tail.attributes, pointFormat, r);
  }
}

// The hierarchy EVLR's payload: pages, children's before their parent's, so that the root page, last,
// can point to every other. dataOffset: the file offset of the payload's first byte.
std::vector<uint8_t> CopcWriter::State::hierarchy(uint64_t dataOffset, uint64_t& rootOffset,
                                                  uint64_t& rootSize) const {
  std::map<NodeKey, Entry> all;
  for (const auto& [key, entry] : nodes)
    all.emplace(key, entry);
  if (all.empty()) all.emplace(NodeKey{}, Entry{}); // an empty octree is an empty root
  // Ancestors without points of their own, so that every node is reachable from the root.
  std::vector<NodeKey> keys;
  for (const auto& [key, entry] : all)
    keys.push_back(key);
  for (NodeKey key : keys)
    while (key.level > 0) {
      key = key.parent();
      if (!all.emplace(key, Entry{}).second) break;
    }
  auto hasChildren = [&](const NodeKey& k) {
    for (int i = 0; i < 8; ++i)
      if (all.count(k.child(i))) return true;
    return false;
  };
  const int step = options.hierarchyStepSize;
  std::vector<uint8_t> out;
  // Writes the page of `top`'s subtree (after the pages it refers to); returns its offset and size.
  auto writePage = [&](auto& self, const NodeKey& top) -> std::pair<uint64_t, uint64_t> {
    std::map<NodeKey, Entry> page;
    std::vector<NodeKey> stack{top};
    while (!stack.empty()) {
      const NodeKey k = stack.back();
      stack.pop_back();
      if (k.level - top.level == step && hasChildren(k)) {
        const auto [offset, size] = self(self, k);
        page[k] = Entry{offset, int32_t(size), -1};
        continue;
      }
      page[k] = all.at(k);
      for (int i = 0; i < 8; ++i)
        if (all.count(k.child(i))) stack.push_back(k.child(i));
    }
    std::vector<uint8_t> bytes;
    for (const auto& [key, entry] : page)
      storeEntry(bytes, key, entry);
    if (bytes.size() > size_t(INT32_MAX))
      fail(path, "a COPC hierarchy page would exceed 2 GiB; write fewer levels a page");
    const uint64_t offset = dataOffset + out.size();
    out.insert(out.end(), bytes.begin(), bytes.end());
    return {offset, bytes.size()};
  };
  std::tie(rootOffset, rootSize) = writePage(writePage, NodeKey{});
  return out;
}

CopcWriter::CopcWriter(std::filesystem::path path, const lod::OctreeMetadata& metadata, bool averagedColors,
                       const CopcWriteOptions& options)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.path = std::move(path);
  s.metadata = metadata;
  s.options = options;
  s.averagedColors = averagedColors;
  assert(options.hierarchyStepSize >= 1);
  s.pointFormat = metadata.fields.color ? 7 : 6;
  const TailFormat& tail = options.tail;
  if (tail.lasPointFormat >= 0) {
    if (tail.lasPointFormat >= 6 && tail.lasPointFormat <= 8)
      s.pointFormat = tail.lasPointFormat;
    else if (tail.attributes.nir)
      s.pointFormat = 8;
  }
  s.recordLength =
      static_cast<uint16_t>(las::kRecordSize[size_t(s.pointFormat)] + tail.attributes.extraBytes);
  s.layout = laz::encoderLayout(s.pointFormat, s.recordLength, laz::kVariableChunks);
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(metadata.scale[a]) || metadata.scale[a] == 0.0 || !std::isfinite(metadata.offset[a]))
      fail(s.path, "the octree's scale/offset cannot be written as LAS");

  s.header();
  std::vector<uint8_t> info(kInfoBytes, 0); // filled in at commit
  const std::vector<std::vector<uint8_t>> vlrs = {
      las::vlrBytes("copc", 1, "COPC info", info),
      las::vlrBytes("laszip encoded", 22204, "LAZ by pointrast", laz::laszipVlrPayload(s.layout))};
  for (const auto& v : vlrs)
    s.prefix.insert(s.prefix.end(), v.begin(), v.end());
  uint32_t vlrCount = 2;
  if (tail.attributes.extraBytes > 0 && !tail.extraBytesDescriptors.empty() &&
      tail.extraBytesDescriptors.size() <= UINT16_MAX) {
    const std::vector<uint8_t> v = las::vlrBytes("LASF_Spec", 4, "Extra bytes", tail.extraBytesDescriptors);
    s.prefix.insert(s.prefix.end(), v.begin(), v.end());
    ++vlrCount;
  }
  if (!options.wkt.empty()) {
    if (options.wkt.size() + 1 > UINT16_MAX)
      fail(s.path, "the coordinate system's WKT is too long for a VLR");
    std::vector<uint8_t> wkt(options.wkt.begin(), options.wkt.end());
    wkt.push_back(0); // null-terminated, as R15 2.5 asks of WKT
    const std::vector<uint8_t> v =
        las::vlrBytes("LASF_Projection", kWktRecord, "OGC WKT coordinate system", wkt);
    s.prefix.insert(s.prefix.end(), v.begin(), v.end());
    ++vlrCount;
  }
  s.pointOffset = s.prefix.size();
  storeLE<uint32_t>(s.prefix.data() + las::kPointOffset, uint32_t(s.pointOffset));
  storeLE<uint32_t>(s.prefix.data() + las::kVlrCount, vlrCount);
  s.next = s.pointOffset + 8;

  std::error_code ec;
  if (std::filesystem::exists(std::filesystem::symlink_status(s.path, ec)))
    fail(s.path, "already exists (the octree is written into a new file)");
  // A name of this process: what a killed build left (another pid) never blocks a new one.
  s.work = partialPath(s.path);
  removeStalePartials(s.path);
  std::filesystem::remove_all(s.work, ec);
  if (!std::filesystem::create_directory(s.work, ec))
    fail(s.path, "cannot create " + s.work.string() + ": " +
                     (ec ? ec.message() : std::string("a folder of that name exists")));
  s.file = s.work / s.path.filename();
  s.fd = ::open(s.file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (s.fd < 0) {
    const int error = errno;
    std::filesystem::remove_all(s.work, ec);
    s.failWrite(error);
  }
}

CopcWriter::~CopcWriter() {
  State& s = *state_;
  if (s.fd >= 0) ::close(s.fd);
  if (s.committed) return;
  std::error_code ignored;
  std::filesystem::remove_all(s.work, ignored);
}

const std::filesystem::path& CopcWriter::workingDir() const {
  return state_->work;
}

CopcWriter::EncodedNode CopcWriter::encodeNode(const NodeKey& key, const PointRecord* records,
                                               size_t count) const {
  return encodeNode(key, records, nullptr, count);
}

CopcWriter::EncodedNode CopcWriter::encodeNode(const NodeKey& key, const PointRecord* records,
                                               const uint8_t* tails, size_t count) const {
  const State& s = *state_;
  if (s.options.tail.bytes() == 0) tails = nullptr;
  // Hierarchy entries count points and bytes in int32.
  if (count > size_t(INT32_MAX))
    fail(s.path, strFormat("node %d-%d-%d-%d holds %zu points, more than a COPC node can (2^31 - 1); "
                           "build with fewer --leaf-points",
                           key.level, key.x, key.y, key.z, count));
  EncodedNode node;
  node.count = count;
  for (size_t k = 0; k < count; ++k) {
    const PointRecord& p = records[k];
    node.qmin[0] = std::min(node.qmin[0], p.x), node.qmax[0] = std::max(node.qmax[0], p.x);
    node.qmin[1] = std::min(node.qmin[1], p.y), node.qmax[1] = std::max(node.qmax[1], p.y);
    node.qmin[2] = std::min(node.qmin[2], p.z), node.qmax[2] = std::max(node.qmax[2], p.z);
    const unsigned rn = (s.metadata.fields.returnNumber ? p.returnNumber : 1) & 0x0F;
    if (rn >= 1) ++node.byReturn[rn - 1];
  }
  if (count == 0) return node;
  const TailFormat& tail = s.options.tail;
  if (tails && tail.layout.gpsTime >= 0) {
    node.gpsMin = node.gpsMax = loadTail<double>(tails, tail.layout.gpsTime);
    for (size_t k = 1; k < count; ++k) {
      const double t = loadTail<double>(tails + k * tail.bytes(), tail.layout.gpsTime);
      node.gpsMin = std::min(node.gpsMin, t);
      node.gpsMax = std::max(node.gpsMax, t);
    }
  }
  thread_local std::vector<uint8_t> raw;
  s.records(records, tails, count, raw);
  std::unique_ptr<laz::ChunkEncoder> encoder;
  {
    std::lock_guard lock(s.encodersMutex);
    if (!s.encoders.empty()) {
      encoder = std::move(s.encoders.back());
      s.encoders.pop_back();
    }
  }
  if (!encoder) encoder = std::make_unique<laz::ChunkEncoder>(s.layout);
  node.bytes = encoder->encode(raw.data(), count);
  std::lock_guard lock(s.encodersMutex);
  s.encoders.push_back(std::move(encoder));
  if (node.bytes.size() > size_t(INT32_MAX))
    fail(s.path, strFormat("node %d-%d-%d-%d compresses to more than 2 GiB, more than a COPC node can hold; "
                           "build with fewer --leaf-points",
                           key.level, key.x, key.y, key.z));
  return node;
}

// A node given its offset (in turn order): its entry and its share of the header's counts and bounds.
void CopcWriter::State::place(const NodeKey& key, const EncodedNode& node, uint64_t offset) {
  nodes.push_back({key, Entry{offset, int32_t(node.bytes.size()), int32_t(node.count)}});
  count += node.count;
  for (int a = 0; a < 3; ++a) {
    qmin[a] = std::min(qmin[a], node.qmin[a]);
    qmax[a] = std::max(qmax[a], node.qmax[a]);
  }
  for (size_t i = 0; i < byReturn.size(); ++i)
    byReturn[i] += node.byReturn[i];
  if (options.tail.layout.gpsTime >= 0) {
    gpsMin = anyGps ? std::min(gpsMin, node.gpsMin) : node.gpsMin;
    gpsMax = anyGps ? std::max(gpsMax, node.gpsMax) : node.gpsMax;
    anyGps = true;
  }
}

uint64_t CopcWriter::reserve(const NodeKey& key) {
  State& s = *state_;
  assert(!s.committed);
  std::lock_guard lock(s.turnsMutex);
  s.turns.push_back({key, {}, false});
  return s.firstTurn + s.turns.size() - 1;
}

void CopcWriter::fill(uint64_t turn, EncodedNode node) {
  State& s = *state_;
  // The nodes that this fill gives an offset, written after the lock is released.
  std::vector<std::pair<uint64_t, EncodedNode>> ready;
  {
    std::lock_guard lock(s.turnsMutex);
    assert(turn >= s.firstTurn && turn - s.firstTurn < s.turns.size());
    State::Turn& t = s.turns[size_t(turn - s.firstTurn)];
    assert(!t.filled);
    t.node = std::move(node);
    t.filled = true;
    while (!s.turns.empty() && s.turns.front().filled) {
      State::Turn& front = s.turns.front();
      if (front.node.count > 0) {
        const uint64_t offset = s.next;
        s.next += front.node.bytes.size();
        s.place(front.key, front.node, offset);
        ready.emplace_back(offset, std::move(front.node));
      }
      s.turns.pop_front();
      ++s.firstTurn;
    }
  }
  for (const auto& [offset, n] : ready)
    s.pwriteAll(offset, n.bytes.data(), n.bytes.size());
}

void CopcWriter::writeNode(const NodeKey& key, const PointRecord* records, size_t count) {
  writeNode(key, records, nullptr, count);
}

void CopcWriter::writeNode(const NodeKey& key, const PointRecord* records, const uint8_t* tails,
                           size_t count) {
  State& s = *state_;
  const size_t tailBytes = tails ? s.options.tail.bytes() : 0;
  State::Waiting w{key, reserve(key), std::vector<PointRecord>(records, records + count), {}};
  if (tailBytes) w.tails.assign(tails, tails + count * tailBytes);
  std::lock_guard lock(s.waitingMutex);
  s.waiting.push_back(std::move(w));
}

void CopcWriter::compressWaiting() {
  State& s = *state_;
  State::Waiting w;
  {
    std::lock_guard lock(s.waitingMutex);
    if (s.waiting.empty()) return;
    w = std::move(s.waiting.front());
    s.waiting.pop_front();
  }
  fill(w.turn,
       encodeNode(w.key, w.records.data(), w.tails.empty() ? nullptr : w.tails.data(), w.records.size()));
}

void CopcWriter::commit() {
  State& s = *state_;
  assert(!s.committed && s.fd >= 0);
  for (;;) {
    {
      std::lock_guard lock(s.waitingMutex);
      if (s.waiting.empty()) break;
    }
    compressWaiting();
  }
  assert(s.turns.empty());
  // The chunk table, in the order the chunks lie in the file.
  std::vector<laz::Chunk> table;
  table.reserve(s.nodes.size());
  for (const auto& [key, entry] : s.nodes)
    table.push_back({entry.offset, uint64_t(entry.byteSize), 0, uint64_t(entry.pointCount)});
  const std::vector<uint8_t> chunkTable = laz::encodeChunkTable(table, true);
  const uint64_t tableOffset = s.next;
  s.pwriteAll(tableOffset, chunkTable.data(), chunkTable.size());
  uint8_t offsetBytes[8];
  storeLE<int64_t>(offsetBytes, int64_t(tableOffset));
  s.pwriteAll(s.pointOffset, offsetBytes, 8);

  const uint64_t evlrStart = tableOffset + chunkTable.size();
  uint64_t rootOffset = 0, rootSize = 0;
  const std::vector<uint8_t> pages = s.hierarchy(evlrStart + kEvlrHeaderSize, rootOffset, rootSize);
  std::vector<uint8_t> evlr(kEvlrHeaderSize, 0);
  las::copyString(evlr.data() + 2, 16, "copc");
  storeLE<uint16_t>(evlr.data() + 18, 1000);
  storeLE<uint64_t>(evlr.data() + 20, pages.size());
  las::copyString(evlr.data() + 28, 32, "EPT hierarchy");
  evlr.insert(evlr.end(), pages.begin(), pages.end());
  s.pwriteAll(evlrStart, evlr.data(), evlr.size());
  s.fileBytes = evlrStart + evlr.size();

  // The info VLR's payload, right after the header and its VLR header.
  uint8_t* info = s.prefix.data() + las::kHeaderSize14 + las::kVlrHeaderSize;
  const Bounds& cube = s.metadata.cube;
  const double half = (cube.max.x - cube.min.x) / 2;
  for (int a = 0; a < 3; ++a)
    storeLE<double>(info + 8 * a, cube.min[a] + half);
  storeLE<double>(info + 24, half);
  storeLE<double>(info + 32, s.metadata.spacing);
  storeLE<uint64_t>(info + 40, rootOffset);
  storeLE<uint64_t>(info + 48, rootSize);
  // The GPS time range (0..0 where the records hold none); the reserved words stay 0.
  storeLE<double>(info + 56, s.gpsMin);
  storeLE<double>(info + 64, s.gpsMax);

  uint8_t* h = s.prefix.data();
  Bounds bounds;
  if (s.count > 0)
    bounds = boundsFromQuantized(s.qmin, s.qmax, s.metadata.scale, s.metadata.offset);
  else
    bounds.min = bounds.max = glm::dvec3(0);
  for (int a = 0; a < 3; ++a) {
    storeLE<double>(h + las::kMaxX + 16 * a, bounds.max[a]);
    storeLE<double>(h + las::kMaxX + 16 * a + 8, bounds.min[a]);
  }
  // Formats 6-10 leave the legacy counts 0 (R15 2.4).
  storeLE<uint64_t>(h + las::kEvlrStart, evlrStart);
  storeLE<uint32_t>(h + las::kEvlrCount, 1);
  storeLE<uint64_t>(h + las::kCount64, s.count);
  for (size_t i = 0; i < 15; ++i)
    storeLE<uint64_t>(h + las::kByReturn64 + 8 * i, s.byReturn[i]);
  s.pwriteAll(0, s.prefix.data(), s.prefix.size());

  const int closed = ::close(s.fd);
  s.fd = -1;
  if (closed != 0) s.failWrite(errno);
  std::error_code ec;
  std::filesystem::rename(s.file, s.path, ec);
  if (ec) s.failWrite(ec.value());
  s.committed = true;
  std::filesystem::remove_all(s.work, ec);
}

uint64_t CopcWriter::bytes() const {
  return state_->fileBytes;
}

// ---- CopcNodeSink -----------------------------------------------------------------------------------------

void CopcNodeSink::writeNode(const NodeKey& key, const PointRecord* records, const uint8_t* tails,
                             size_t count) {
  writer_.writeNode(key, records, tails, count);
}

std::unique_ptr<lod::PreparedNode> CopcNodeSink::prepare(const NodeKey& key, const PointRecord* records,
                                                         const uint8_t* tails, size_t count) const {
  auto prepared = std::make_unique<Prepared>();
  prepared->node = writer_.encodeNode(key, records, tails, count);
  return prepared;
}

void CopcNodeSink::writePrepared(const NodeKey& key, lod::PreparedNode* prepared, const PointRecord* records,
                                 const uint8_t* tails, size_t count) {
  auto* p = dynamic_cast<Prepared*>(prepared);
  if (!p) return writeNode(key, records, tails, count);
  p->turn = writer_.reserve(key);
  p->reserved = true;
}

void CopcNodeSink::finishPrepared(std::unique_ptr<lod::PreparedNode> prepared) const {
  // A node that spans chunks, left waiting by writeNode() in the builder's order, is encoded here on
  // the indexing threads: the turns after it keep their bytes until it is.
  writer_.compressWaiting();
  auto* p = dynamic_cast<Prepared*>(prepared.get());
  if (p && p->reserved) writer_.fill(p->turn, std::move(p->node));
}

// ---- inputs and the build ---------------------------------------------------------------------------------

std::string inputsWkt(const std::vector<std::filesystem::path>& inputs) {
  std::string wkt;
  std::filesystem::path from;
  for (const std::filesystem::path& path : inputs) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext != ".las" && ext != ".laz") continue;
    const InputFile file(path);
    const LasHeader hd = readLasHeader(file, true);
    std::string own;
    bool geoKeys = false;
    for (const LasVlr& vlr : hd.vlrs) {
      if (vlr.userId != "LASF_Projection") continue;
      if (vlr.recordId == kGeoKeysRecord) geoKeys = true;
      if (vlr.recordId != kWktRecord || vlr.length == 0) continue;
      own.resize(vlr.length);
      file.readAt(vlr.dataOffset, own.data(), own.size());
      own.resize(std::strlen(own.c_str())); // up to its terminating null
    }
    if (own.empty()) {
      if (geoKeys)
        warn(path, "its coordinate system is given as GeoTIFF keys only, which COPC cannot hold (it stores "
                   "WKT); the octree is written without one");
      continue;
    }
    if (wkt.empty()) {
      wkt = own;
      from = path;
    } else if (own != wkt) {
      fail(path, "its coordinate system (WKT) differs from that of " + from.filename().string() +
                     "; a COPC file holds one: build them separately or reproject first");
    }
  }
  return wkt;
}

CopcBuildReport buildCopc(const std::vector<std::filesystem::path>& inputs,
                          const std::filesystem::path& output, const LodBuildOptions& options,
                          CopcWriteOptions writeOptions) {
  OctreeBuilder builder(inputs, options);
  writeOptions.wkt = inputsWkt(inputs);
  const lod::OctreeMetadata& metadata = builder.scan();
  writeOptions.tail = builder.tail();
  CopcWriter writer(output, metadata, options.averageColors, writeOptions);
  CopcNodeSink sink(writer);
  CopcBuildReport report;
  // Temporary chunk files live in the writer's folder: whatever ends the build, they go with it.
  report.build = builder.build(sink, writer.workingDir() / "chunks");
  const lod::PhaseClock clock;
  writer.commit();
  report.build.phases.push_back(clock.done("commit", report.build.octree.points));
  report.build.seconds += report.build.phases.back().seconds;
  report.bytes = writer.bytes();
  return report;
}

} // namespace pointrast::io

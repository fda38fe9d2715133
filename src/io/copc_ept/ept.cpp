// EPT reader: ept.json (a small DOM parse after a nesting check), hierarchy files (a SAX parse that
// accepts one flat object of "D-X-Y-Z": count and nothing else, so a hostile file costs no more than
// its entries), node data decoded by dataType.
#include "io/copc_ept/ept.h"

#include <algorithm>
#include <cstring>
#include <mutex>
#include <set>
#include <unordered_map>

#include <nlohmann/json.hpp>
#include <zstd.h>

#include "cloud/lod_tails.h"
#include "io/io_util.h"
#include "io/las/las_records.h"
#include "io/las/laz_reader.h"

namespace pointrast::io {

using namespace detail;
using lod::NodeInfo;
using lod::NodeKey;
using nlohmann::json;

namespace {

constexpr uint64_t kMaxEptJsonBytes = uint64_t(16) << 20;    // real ones hold a few KB
constexpr uint64_t kMaxHierarchyBytes = uint64_t(256) << 20; // entwine splits hierarchies far below this
constexpr int kMaxJsonDepth = 32;                            // ept.json nests 3 deep
constexpr int32_t kMaxLevel = 30;                            // int32 cell coordinates

std::string keyName(const NodeKey& k) {
  return strFormat("%d-%d-%d-%d", k.level, k.x, k.y, k.z);
}

std::string readTextFile(const std::filesystem::path& path, uint64_t maxBytes, const char* what) {
  InputFile file(path);
  if (file.size() > maxBytes)
    fail(path, strFormat("%s of %llu bytes is larger than the %llu MB an EPT dataset needs", what,
                         static_cast<unsigned long long>(file.size()),
                         static_cast<unsigned long long>(maxBytes >> 20)));
  std::string text(file.size(), '\0');
  file.readAt(0, text.data(), text.size());
  return text;
}

// JSON nesting depth outside strings; the DOM parser and its destructor are not trusted with more.
void checkNesting(const std::filesystem::path& path, const std::string& text) {
  int depth = 0;
  bool inString = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) fail(path, strFormat("JSON nested more than %d deep", kMaxJsonDepth));
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

// "D-X-Y-Z": four decimal numbers without signs, the level within 0..kMaxLevel, coordinates within it.
bool parseKey(const std::string& s, NodeKey& key) {
  int64_t v[4] = {};
  size_t at = 0;
  for (int i = 0; i < 4; ++i) {
    const size_t start = at;
    while (at < s.size() && at - start < 11 && s[at] >= '0' && s[at] <= '9')
      v[i] = v[i] * 10 + (s[at++] - '0');
    if (at == start || at - start > 10) return false;
    if (i < 3 && (at >= s.size() || s[at++] != '-')) return false;
  }
  if (at != s.size() || v[0] > kMaxLevel) return false;
  const int64_t cells = int64_t(1) << v[0];
  if (v[1] >= cells || v[2] >= cells || v[3] >= cells) return false;
  key = {int32_t(v[0]), int32_t(v[1]), int32_t(v[2]), int32_t(v[3])};
  return true;
}

bool inSubtree(const NodeKey& key, const NodeKey& root) {
  const int32_t up = key.level - root.level;
  return up >= 0 && (key.x >> up) == root.x && (key.y >> up) == root.y && (key.z >> up) == root.z;
}

// One hierarchy file: a flat object of "D-X-Y-Z": count (count -1: the subtree's own file).
class HierarchySax : public nlohmann::json_sax<json> {
public:
  std::vector<std::pair<NodeKey, int64_t>> entries;
  std::string error;

  bool null() override { return bad("a null"); }
  bool boolean(bool) override { return bad("a boolean"); }
  bool number_integer(number_integer_t v) override { return value(v); }
  bool number_unsigned(number_unsigned_t v) override {
    return v > uint64_t(INT64_MAX) ? bad("a count beyond 2^63") : value(int64_t(v));
  }
  bool number_float(number_float_t, const string_t&) override { return bad("a fractional count"); }
  bool string(string_t&) override { return bad("a string"); }
  bool binary(binary_t&) override { return bad("binary data"); }
  bool start_object(std::size_t) override { return ++depth_ == 1 ? true : bad("a nested object"); }
  bool key(string_t& k) override {
    if (!parseKey(k, pending_))
      return bad(("the key \"" + k.substr(0, 40) + "\", not a node D-X-Y-Z").c_str());
    return true;
  }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return bad("an array"); }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception&) override {
    error = strFormat("is not valid JSON (at byte %zu)", position);
    return false;
  }

private:
  bool value(int64_t v) {
    if (depth_ != 1) return bad("a count outside the object");
    if (v < -1) return bad("a negative count");
    entries.emplace_back(pending_, v);
    return true;
  }
  bool bad(const char* what) {
    error = std::string("holds ") + what + " where a node's count belongs";
    return false;
  }
  int depth_ = 0;
  NodeKey pending_;
};

enum class DimKind { Signed, Unsigned, Float };

struct Dimension {
  std::string name;
  DimKind kind = DimKind::Signed;
  uint32_t size = 0;
  uint32_t offset = 0; // within a binary point
  double scale = 1, shift = 0;
  bool scaled = false;
};

// A value of the schema's binary layout.
double loadNumber(const uint8_t* p, const Dimension& d) {
  switch (d.kind) {
  case DimKind::Float:
    return d.size == 4 ? double(loadLE<float>(p)) : loadLE<double>(p);
  case DimKind::Signed:
    switch (d.size) {
    case 1:
      return double(int8_t(p[0]));
    case 2:
      return loadLE<int16_t>(p);
    case 4:
      return loadLE<int32_t>(p);
    default:
      return double(loadLE<int64_t>(p));
    }
  case DimKind::Unsigned:
    switch (d.size) {
    case 1:
      return p[0];
    case 2:
      return loadLE<uint16_t>(p);
    case 4:
      return loadLE<uint32_t>(p);
    default:
      return double(loadLE<uint64_t>(p));
    }
  }
  return 0;
}

template <class T> T clampTo(double v) {
  if (!(v > 0)) return 0;
  return v >= double(std::numeric_limits<T>::max()) ? std::numeric_limits<T>::max() : static_cast<T>(v);
}

struct EptMeta {
  std::filesystem::path root; // the folder
  std::filesystem::path json; // its ept.json
  std::string dataType;       // laszip, binary, zstandard
  std::vector<Dimension> schema;
  uint32_t pointSize = 0;
  const Dimension* xyz[3] = {};
  const Dimension *intensity = nullptr, *returnNumber = nullptr, *classification = nullptr,
                  *pointSourceId = nullptr;
  const Dimension* rgb[3] = {};
  lod::OctreeMetadata octree;
  // The schema's dimensions beyond the record's fields, in schema order, and the tails that carry their
  // bytes as they are stored (binary and zstandard data; a LAZ node's records carry none).
  std::vector<const Dimension*> tail;
  TailFormat tailFormat;
};

Bounds parseBounds(const std::filesystem::path& path, const json& j, const char* name) {
  const json* b = j.contains(name) ? &j.at(name) : nullptr;
  if (!b || !b->is_array() || b->size() != 6)
    fail(path, strFormat("\"%s\" is not an array of 6 numbers", name));
  double v[6];
  for (int i = 0; i < 6; ++i) {
    if (!(*b)[size_t(i)].is_number()) fail(path, strFormat("\"%s\" is not an array of 6 numbers", name));
    v[i] = (*b)[size_t(i)].get<double>();
    if (!std::isfinite(v[i])) fail(path, strFormat("\"%s\" holds a number that is not finite", name));
  }
  Bounds out;
  out.min = {v[0], v[1], v[2]};
  out.max = {v[3], v[4], v[5]};
  if (!(out.min.x <= out.max.x && out.min.y <= out.max.y && out.min.z <= out.max.z))
    fail(path, strFormat("\"%s\" has a minimum above its maximum", name));
  return out;
}

void parseSchema(const std::filesystem::path& path, const json& j, EptMeta& meta) {
  if (!j.contains("schema") || !j["schema"].is_array() || j["schema"].empty())
    fail(path, "\"schema\" is not a non-empty array");
  const json& schema = j["schema"];
  if (schema.size() > 1024) fail(path, "\"schema\" lists more than 1024 dimensions");
  for (const json& d : schema) {
    if (!d.is_object() || !d.contains("name") || !d["name"].is_string() || !d.contains("type") ||
        !d["type"].is_string() || !d.contains("size") || !d["size"].is_number_unsigned())
      fail(path, "a \"schema\" entry lacks a name, type or size");
    Dimension dim;
    dim.name = d["name"].get<std::string>();
    const std::string type = d["type"].get<std::string>();
    const uint64_t size = d["size"].get<uint64_t>();
    if (type == "signed")
      dim.kind = DimKind::Signed;
    else if (type == "unsigned")
      dim.kind = DimKind::Unsigned;
    else if (type == "float")
      dim.kind = DimKind::Float;
    else
      fail(path, strFormat("schema dimension \"%s\" has type \"%s\" (signed, unsigned and float exist)",
                           dim.name.substr(0, 40).c_str(), type.substr(0, 40).c_str()));
    const bool sizeOk = dim.kind == DimKind::Float ? (size == 4 || size == 8)
                                                   : (size == 1 || size == 2 || size == 4 || size == 8);
    if (!sizeOk)
      fail(path, strFormat("schema dimension \"%s\" of type %s has size %llu", dim.name.substr(0, 40).c_str(),
                           type.c_str(), static_cast<unsigned long long>(size)));
    dim.size = uint32_t(size);
    dim.offset = meta.pointSize;
    meta.pointSize += dim.size;
    if (d.contains("scale") || d.contains("offset")) {
      dim.scaled = true;
      dim.scale = d.contains("scale") && d["scale"].is_number() ? d["scale"].get<double>() : 1.0;
      dim.shift = d.contains("offset") && d["offset"].is_number() ? d["offset"].get<double>() : 0.0;
      if (!std::isfinite(dim.scale) || dim.scale == 0 || !std::isfinite(dim.shift))
        fail(path, strFormat("schema dimension \"%s\" has an unusable scale or offset",
                             dim.name.substr(0, 40).c_str()));
    }
    meta.schema.push_back(dim);
  }
  auto find = [&](const char* name) -> const Dimension* {
    for (const Dimension& d : meta.schema)
      if (d.name == name) return &d;
    return nullptr;
  };
  const char* axes[3] = {"X", "Y", "Z"};
  for (int a = 0; a < 3; ++a) {
    meta.xyz[a] = find(axes[a]);
    if (!meta.xyz[a]) fail(path, strFormat("the schema has no %s dimension", axes[a]));
  }
  meta.intensity = find("Intensity");
  meta.returnNumber = find("ReturnNumber");
  meta.classification = find("Classification");
  meta.pointSourceId = find("PointSourceId");
  meta.rgb[0] = find("Red");
  meta.rgb[1] = find("Green");
  meta.rgb[2] = find("Blue");
}

EptMeta parseEptJson(const std::filesystem::path& input) {
  EptMeta meta;
  meta.json = std::filesystem::is_directory(input) ? input / "ept.json" : input;
  meta.root = meta.json.parent_path();
  const std::filesystem::path& path = meta.json;
  const std::string text = readTextFile(path, kMaxEptJsonBytes, "ept.json");
  checkNesting(path, text);
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) fail(path, "is not a JSON object");
  if (!j.contains("dataType") || !j["dataType"].is_string()) fail(path, "has no \"dataType\"");
  meta.dataType = j["dataType"].get<std::string>();
  if (meta.dataType != "laszip" && meta.dataType != "binary" && meta.dataType != "zstandard")
    fail(path, strFormat("dataType \"%s\" is unknown (laszip, binary and zstandard are EPT's)",
                         meta.dataType.substr(0, 40).c_str()));
  if (j.contains("hierarchyType") && j["hierarchyType"] != "json")
    fail(path, "only JSON hierarchies (\"hierarchyType\": \"json\") are read");
  if (!j.contains("points") || !j["points"].is_number_unsigned()) fail(path, "\"points\" is not a count");
  if (!j.contains("span") || !j["span"].is_number_unsigned() || j["span"].get<uint64_t>() == 0 ||
      j["span"].get<uint64_t>() > (uint64_t(1) << 20))
    fail(path, "\"span\" is not a positive count of voxels");
  parseSchema(path, j, meta);

  lod::OctreeMetadata& m = meta.octree;
  m.source = meta.root.filename().string();
  m.format =
      "EPT " +
      (j.contains("version") && j["version"].is_string() ? j["version"].get<std::string>().substr(0, 16)
                                                         : std::string("1.0.0")) +
      " (" + meta.dataType + ")";
  m.cube = parseBounds(path, j, "bounds");
  // EPT's bounds are a cube; a lax writer's box becomes the cube of its longest edge.
  const glm::dvec3 size = m.cube.max - m.cube.min;
  const double edge = std::max({size.x, size.y, size.z});
  if (!(edge > 0)) fail(path, "\"bounds\" is an empty box");
  m.cube.max = m.cube.min + glm::dvec3(edge);
  m.bounds = j.contains("boundsConforming") ? parseBounds(path, j, "boundsConforming") : m.cube;
  m.spacing = edge / double(j["span"].get<uint64_t>());
  m.pointCount = j["points"].get<uint64_t>();
  const bool allScaled = meta.xyz[0]->scaled && meta.xyz[1]->scaled && meta.xyz[2]->scaled;
  if (allScaled) {
    for (int a = 0; a < 3; ++a) {
      m.scale[a] = meta.xyz[a]->scale;
      m.offset[a] = meta.xyz[a]->shift;
    }
  } else {
    const Quantization q = chooseQuantization(path, m.cube);
    m.scale = q.scale;
    m.offset = q.offset;
  }
  m.fields.color = meta.rgb[0] && meta.rgb[1] && meta.rgb[2];
  m.fields.intensity = meta.intensity != nullptr;
  m.fields.returnNumber = meta.returnNumber != nullptr;
  m.fields.classification = meta.classification != nullptr;
  m.fields.pointSourceId = meta.pointSourceId != nullptr;
  if (meta.dataType != "laszip") {
    uint32_t bytes = 0;
    for (const Dimension& d : meta.schema) {
      const bool record = &d == meta.xyz[0] || &d == meta.xyz[1] || &d == meta.xyz[2] ||
                          &d == meta.intensity || &d == meta.returnNumber || &d == meta.classification ||
                          &d == meta.pointSourceId ||
                          (m.fields.color && (&d == meta.rgb[0] || &d == meta.rgb[1] || &d == meta.rgb[2]));
      if (record) continue;
      meta.tail.push_back(&d);
      bytes += d.size;
    }
    // At most 1024 dimensions of 8 bytes (parseSchema).
    meta.tailFormat.attributes.extraBytes = uint16_t(bytes);
    meta.tailFormat.layout = attributeLayout(meta.tailFormat.attributes);
  }
  return meta;
}

// The key a pick shows a dimension under (lod_tails.h): the LAS attributes' names for PDAL's dimensions of
// them, else none (an extra dimension, shown by its own name).
const char* tailKey(const std::string& name) {
  static const std::pair<const char*, const char*> kKeys[] = {
      {"GpsTime", "gps_time"},
      {"NumberOfReturns", "number_of_returns"},
      {"ScanAngleRank", "scan_angle"},
      {"UserData", "user_data"},
      {"Infrared", "nir"},
      {"ClassFlags", "classification_flags"},
      {"ScanChannel", "scanner_channel"},
      {"ScanDirectionFlag", "scan_direction_flag"},
      {"EdgeOfFlightLine", "edge_of_flight_line"},
  };
  for (const auto& [dimension, key] : kKeys)
    if (name == dimension) return key;
  return nullptr;
}

class EptSource : public lod::NodeSource, public lod::NodeTails {
public:
  explicit EptSource(const std::filesystem::path& path) : meta_(parseEptJson(path)) {
    loadHierarchy(NodeKey{});
    const auto root = counts_.find(NodeKey{});
    if (root == counts_.end() || root->second < 0)
      fail(hierarchyPath(NodeKey{}), "does not list the root node 0-0-0-0");
  }

  const lod::OctreeMetadata& metadata() const override { return meta_.octree; }
  const EptMeta& ept() const { return meta_; }

  NodeInfo root() override {
    std::lock_guard lock(mutex_);
    return infoOf(NodeKey{});
  }

  std::vector<NodeInfo> children(const NodeInfo& node) override {
    std::lock_guard lock(mutex_);
    std::vector<NodeInfo> out;
    for (int i = 0; i < 8; ++i) {
      const NodeKey key = node.key.child(i);
      auto it = counts_.find(key);
      if (it == counts_.end()) continue;
      if (it->second < 0) {
        loadHierarchy(key);
        it = counts_.find(key);
        if (it->second < 0)
          fail(hierarchyPath(key), strFormat("does not list node %s", keyName(key).c_str()));
      }
      out.push_back(infoOf(key));
    }
    return out;
  }

  std::vector<PointRecord> readNode(const NodeInfo& node) override { return readPoints(node, nullptr); }

  const TailFormat& tailFormat() const override { return meta_.tailFormat; }

  std::vector<PointRecord> readNodeTails(const NodeInfo& node, std::vector<uint8_t>& tails) override {
    return readPoints(node, &tails);
  }

  std::vector<lod::TailValue> tailValues(const uint8_t* tail) const override {
    std::vector<lod::TailValue> out;
    const uint8_t* p = tail + std::max(meta_.tailFormat.layout.extraBytes, 0);
    for (const Dimension* d : meta_.tail) {
      lod::TailValue v;
      const char* key = tailKey(d->name);
      v.name = key ? key : d->name;
      v.extraBytes = key == nullptr;
      // Integers exact (an 8-byte one would round as a double); a scaled one as its value.
      if (d->scaled)
        v.values.push_back(loadNumber(p, *d) * d->scale + d->shift);
      else if (d->kind == DimKind::Float)
        v.values.push_back(loadNumber(p, *d));
      else if (d->kind == DimKind::Signed)
        v.values.push_back(d->size == 8 ? loadLE<int64_t>(p) : int64_t(loadNumber(p, *d)));
      else
        v.values.push_back(d->size == 8 ? loadLE<uint64_t>(p) : uint64_t(loadNumber(p, *d)));
      out.push_back(std::move(v));
      p += d->size;
    }
    return out;
  }

  uint64_t nodeBytes(const NodeInfo& node) override {
    countOf(node.key); // the node must be known
    std::error_code ec;
    const auto size = std::filesystem::file_size(dataPath(node.key), ec);
    return ec ? 0 : uint64_t(size);
  }

private:
  // A node's records, and where `tails` is given the bytes of the schema's other dimensions beside them
  // (tailFormat().bytes() a point).
  std::vector<PointRecord> readPoints(const NodeInfo& node, std::vector<uint8_t>* tails) {
    const uint64_t count = countOf(node.key);
    std::vector<PointRecord> out;
    if (tails) tails->clear();
    if (count == 0) return out;
    const std::filesystem::path path = dataPath(node.key);
    if (meta_.dataType == "laszip") return readLazNode(path, count);
    std::vector<uint8_t> bytes = meta_.dataType == "binary" ? readBinary(path, count) : readZstd(path, count);
    out.resize(count);
    for (uint64_t i = 0; i < count; ++i)
      out[i] = parsePoint(bytes.data() + i * meta_.pointSize);
    const uint32_t tailBytes = meta_.tailFormat.bytes();
    if (tails && tailBytes > 0) {
      tails->assign(count * tailBytes, 0);
      for (uint64_t i = 0; i < count; ++i) {
        uint8_t* t = tails->data() + i * tailBytes + meta_.tailFormat.layout.extraBytes;
        for (const Dimension* d : meta_.tail) {
          std::memcpy(t, bytes.data() + i * meta_.pointSize + d->offset, d->size);
          t += d->size;
        }
      }
    }
    return out;
  }

  std::filesystem::path hierarchyPath(const NodeKey& key) const {
    return meta_.root / "ept-hierarchy" / (keyName(key) + ".json");
  }
  std::filesystem::path dataPath(const NodeKey& key) const {
    const char* ext = meta_.dataType == "laszip" ? ".laz" : meta_.dataType == "binary" ? ".bin" : ".zst";
    return meta_.root / "ept-data" / (keyName(key) + ext);
  }

  uint64_t countOf(const NodeKey& key) {
    std::lock_guard lock(mutex_);
    auto it = counts_.find(key);
    if (it == counts_.end() || it->second < 0)
      fail(meta_.json, strFormat("node %s is not in the hierarchy read so far", keyName(key).c_str()));
    return uint64_t(it->second);
  }

  NodeInfo infoOf(const NodeKey& key) const {
    NodeInfo info;
    info.key = key;
    info.pointCount = uint64_t(counts_.at(key));
    for (int i = 0; i < 8; ++i)
      if (key.level < kMaxLevel && counts_.count(key.child(i))) info.childMask |= uint8_t(1u << i);
    return info;
  }

  // Reads ept-hierarchy/<key>.json: entries of key's subtree. Each file is read at most once; a second
  // reference to it is a cycle.
  void loadHierarchy(const NodeKey& fileKey) {
    const std::filesystem::path path = hierarchyPath(fileKey);
    if (!files_.insert(fileKey).second) fail(path, "is referenced twice in the hierarchy (a cycle)");
    const std::string text = readTextFile(path, kMaxHierarchyBytes, "a hierarchy file");
    HierarchySax sax;
    const bool ok = json::sax_parse(text, &sax, json::input_format_t::json, true, false);
    if (!ok || !sax.error.empty()) fail(path, sax.error.empty() ? "is not valid JSON" : sax.error);
    for (const auto& [key, count] : sax.entries) {
      if (!inSubtree(key, fileKey))
        fail(path, strFormat("lists node %s, outside the subtree of %s", keyName(key).c_str(),
                             keyName(fileKey).c_str()));
      auto [it, added] = counts_.emplace(key, count);
      if (!added) {
        // A file resolves the -1 its parent file gave its own key; any other repeat is a conflict.
        if (!(it->second < 0 && key == fileKey && count >= 0))
          fail(path, strFormat("lists node %s a second time", keyName(key).c_str()));
        it->second = count;
      }
    }
  }

  std::vector<uint8_t> readBinary(const std::filesystem::path& path, uint64_t count) const {
    InputFile file(path);
    if (file.size() / meta_.pointSize != count || file.size() % meta_.pointSize != 0)
      fail(path,
           strFormat("holds %llu bytes; %llu points of %u bytes are %llu",
                     static_cast<unsigned long long>(file.size()), static_cast<unsigned long long>(count),
                     meta_.pointSize, static_cast<unsigned long long>(count * meta_.pointSize)));
    std::vector<uint8_t> bytes(file.size());
    file.readAt(0, bytes.data(), bytes.size());
    return bytes;
  }

  // zstd-compressed binary points. Decompressed as a stream into a buffer that grows with the output,
  // never past the hierarchy's count: a frame claiming more costs nothing before it is refused.
  std::vector<uint8_t> readZstd(const std::filesystem::path& path, uint64_t count) const {
    InputFile file(path);
    std::vector<uint8_t> in(file.size());
    file.readAt(0, in.data(), in.size());
    if (count > UINT64_MAX / meta_.pointSize) fail(path, "its node's count is impossibly large");
    const uint64_t want = count * meta_.pointSize;
    std::unique_ptr<ZSTD_DStream, size_t (*)(ZSTD_DStream*)> stream(ZSTD_createDStream(), ZSTD_freeDStream);
    if (!stream) throw std::bad_alloc();
    ZSTD_initDStream(stream.get());
    std::vector<uint8_t> out(std::min<uint64_t>(want, std::max<uint64_t>(1 << 16, in.size() * 8)));
    ZSTD_inBuffer src{in.data(), in.size(), 0};
    uint64_t produced = 0;
    size_t ret = 1;
    while (src.pos < src.size || ret != 0) {
      if (produced == out.size()) {
        if (out.size() == want)
          fail(path,
               strFormat("decompresses to more than %llu points", static_cast<unsigned long long>(count)));
        out.resize(std::min<uint64_t>(want, out.size() * 2));
      }
      ZSTD_outBuffer dst{out.data() + produced, out.size() - produced, 0};
      ret = ZSTD_decompressStream(stream.get(), &dst, &src);
      if (ZSTD_isError(ret)) fail(path, strFormat("is not valid zstd data (%s)", ZSTD_getErrorName(ret)));
      produced += dst.pos;
      if (src.pos == src.size && dst.pos == 0 && ret != 0) fail(path, "ends inside its zstd frame");
    }
    if (produced != want)
      fail(path, strFormat("decompresses to %llu bytes; %llu points of %u bytes are %llu",
                           static_cast<unsigned long long>(produced), static_cast<unsigned long long>(count),
                           meta_.pointSize, static_cast<unsigned long long>(want)));
    out.resize(produced);
    return out;
  }

  PointRecord parsePoint(const uint8_t* p) const {
    PointRecord r;
    const lod::OctreeMetadata& m = meta_.octree;
    int32_t* q[3] = {&r.x, &r.y, &r.z};
    for (int a = 0; a < 3; ++a) {
      const Dimension& d = *meta_.xyz[a];
      const double v = loadNumber(p + d.offset, d);
      if (d.kind != DimKind::Float && d.scaled && d.size <= 4 && d.scale == m.scale[a] &&
          d.shift == m.offset[a])
        *q[a] = int32_t(std::clamp(v, -2147483648.0, 2147483647.0)); // the schema's own integers
      else
        *q[a] = quantize(d.scaled ? v * d.scale + d.shift : v, m.scale[a], m.offset[a]);
    }
    if (meta_.octree.fields.color)
      for (int c = 0; c < 3; ++c)
        r.rgb[c] = clampTo<uint16_t>(loadNumber(p + meta_.rgb[c]->offset, *meta_.rgb[c]));
    if (meta_.intensity)
      r.intensity = clampTo<uint16_t>(loadNumber(p + meta_.intensity->offset, *meta_.intensity));
    if (meta_.returnNumber)
      r.returnNumber = clampTo<uint8_t>(loadNumber(p + meta_.returnNumber->offset, *meta_.returnNumber));
    if (meta_.classification)
      r.classification =
          clampTo<uint8_t>(loadNumber(p + meta_.classification->offset, *meta_.classification));
    if (meta_.pointSourceId)
      r.pointSourceId = clampTo<uint16_t>(loadNumber(p + meta_.pointSourceId->offset, *meta_.pointSourceId));
    return r;
  }

  // A node stored as a LAZ file: its records, requantized when its scale or offset differs from the
  // dataset's.
  std::vector<PointRecord> readLazNode(const std::filesystem::path& path, uint64_t count) const {
    InputFile file(path);
    const laz::LazFile laz = laz::openLaz(file);
    const LasHeader& hd = laz.header;
    if (hd.pointCount != count)
      fail(path,
           strFormat("holds %llu points, the hierarchy says %llu",
                     static_cast<unsigned long long>(hd.pointCount), static_cast<unsigned long long>(count)));
    const lod::OctreeMetadata& m = meta_.octree;
    const bool sameQuantization = hd.scale == m.scale && hd.offset == m.offset;
    const bool extended = las::isExtended(hd.pointFormat);
    const int rgbOffset = hd.rgbOffset();
    std::vector<PointRecord> out;
    laz::ChunkDecoder decoder(laz.layout);
    std::vector<uint8_t> bytes, records;
    for (size_t c = 0; c < laz.chunks.size(); ++c) {
      laz::decodeChunk(file, laz, c, decoder, bytes, records);
      for (size_t at = 0; at + hd.recordLength <= records.size(); at += hd.recordLength) {
        PointRecord r = toPointRecord(records.data() + at, extended, rgbOffset);
        if (!sameQuantization) {
          int32_t* q[3] = {&r.x, &r.y, &r.z};
          for (int a = 0; a < 3; ++a)
            *q[a] = quantize(*q[a] * hd.scale[a] + hd.offset[a], m.scale[a], m.offset[a]);
        }
        out.push_back(r);
      }
    }
    return out;
  }

  EptMeta meta_;
  std::mutex mutex_;
  std::unordered_map<NodeKey, int64_t, lod::NodeKeyHash> counts_;
  std::set<NodeKey> files_;
};

} // namespace

std::unique_ptr<lod::NodeSource> openEpt(const std::filesystem::path& path) {
  try {
    return std::make_unique<EptSource>(path);
  } catch (const json::exception& e) {
    fail(path, strFormat("is not a valid EPT ept.json (%s)", e.what()));
  }
}

bool looksLikeEpt(const std::filesystem::path& path) {
  std::error_code ec;
  if (path.filename() == "ept.json") return std::filesystem::is_regular_file(path, ec);
  return std::filesystem::is_directory(path, ec) && std::filesystem::is_regular_file(path / "ept.json", ec);
}

} // namespace pointrast::io

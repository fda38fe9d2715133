// EPT datasets made from lone-star.copc.laz (ept_test_data.h) in binary, zstandard and laszip node data:
// every node equals the COPC node of the same key, readCloud equals the COPC file's cloud, and hostile
// datasets are refused with one line.
#include <map>
#include <thread>

#include "io/copc_ept/copc.h"
#include "io/copc_ept/ept.h"
#include "io/ept_test_data.h"
#include "io/io_test_util.h"

using pointrast::InputError;
using pointrast::PointCloud;
using pointrast::PointRecord;
using namespace pointrast::io;
using iotest::data;
using iotest::quiet;
using pointrast::lod::NodeInfo;
using pointrast::lod::NodeKey;

namespace {

namespace fs = std::filesystem;
const char* kCopc = "laz/lone-star.copc.laz";

std::map<NodeKey, NodeInfo> nodesOf(pointrast::lod::NodeSource& source) {
  std::map<NodeKey, NodeInfo> nodes;
  pointrast::lod::forEachNode(source, [&](const NodeInfo& n) {
    nodes[n.key] = n;
    return true;
  });
  return nodes;
}

class EptEncodings : public ::testing::TestWithParam<const char*> {};

TEST_P(EptEncodings, EveryNodeEqualsTheCopcNode) {
  POINTRAST_REQUIRE_DATA();
  iotest::TempDir dir;
  const fs::path json = iotest::writeEpt(data(kCopc), dir / "ept", GetParam());
  const auto ept = openEpt(json);
  const auto copc = openCopc(data(kCopc));
  const auto& m = ept->metadata();
  EXPECT_EQ(m.format, std::string("EPT 1.0.0 (") + GetParam() + ")");
  EXPECT_EQ(m.pointCount, 518862u);
  EXPECT_EQ(m.scale, copc->metadata().scale);
  EXPECT_EQ(m.offset, copc->metadata().offset);
  EXPECT_NEAR(m.spacing, copc->metadata().spacing, 1e-3);
  EXPECT_EQ(m.cube.min, copc->metadata().cube.min);
  EXPECT_FALSE(m.fields.color);
  EXPECT_TRUE(m.fields.intensity && m.fields.classification && m.fields.returnNumber &&
              m.fields.pointSourceId);
  const auto eptNodes = nodesOf(*ept), copcNodes = nodesOf(*copc);
  ASSERT_EQ(eptNodes.size(), copcNodes.size());
  for (const auto& [key, node] : copcNodes) {
    ASSERT_TRUE(eptNodes.count(key)) << key.potreeName();
    const NodeInfo& e = eptNodes.at(key);
    EXPECT_EQ(e.pointCount, node.pointCount);
    EXPECT_EQ(e.childMask, node.childMask);
    EXPECT_EQ(ept->readNode(e), copc->readNode(node)) << key.potreeName();
    EXPECT_GT(ept->nodeBytes(e), 0u);
  }
  // Also when the nodes are read from several threads, the subtree's hierarchy file among them.
  const auto fresh = openEpt(json.parent_path());
  std::vector<NodeInfo> list;
  for (const auto& [key, node] : nodesOf(*fresh))
    list.push_back(node);
  std::vector<std::vector<PointRecord>> got(list.size());
  std::vector<std::thread> threads;
  for (int t = 0; t < 3; ++t)
    threads.emplace_back([&, t] {
      for (size_t i = size_t(t); i < list.size(); i += 3)
        got[i] = fresh->readNode(list[i]);
    });
  for (auto& t : threads)
    t.join();
  for (size_t i = 0; i < list.size(); ++i)
    EXPECT_EQ(got[i].size(), list[i].pointCount);
}

TEST_P(EptEncodings, ReadCloudAndProbe) {
  POINTRAST_REQUIRE_DATA();
  iotest::TempDir dir;
  const fs::path json = iotest::writeEpt(data(kCopc), dir / "ept", GetParam());
  EXPECT_EQ(iotest::formatOf(json), "EPT");
  EXPECT_EQ(iotest::formatOf(json.parent_path()), "EPT");
  const PointCloud cloud = readCloud(json, quiet());
  const PointCloud copc = readCloud(data(kCopc), quiet());
  ASSERT_EQ(cloud.size(), copc.size());
  EXPECT_EQ(cloud.bounds.min, copc.bounds.min);
  EXPECT_EQ(cloud.bounds.max, copc.bounds.max);
  // Same points, in another order (depth-first nodes, not file order): compare sorted positions.
  std::vector<std::array<int32_t, 3>> a(cloud.size()), b(copc.size());
  for (size_t i = 0; i < a.size(); ++i) {
    a[i] = {cloud.positions[3 * i], cloud.positions[3 * i + 1], cloud.positions[3 * i + 2]};
    b[i] = {copc.positions[3 * i], copc.positions[3 * i + 1], copc.positions[3 * i + 2]};
  }
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
  const FileInfo info = probeFile(json.parent_path());
  EXPECT_STREQ(info.format->name, "EPT");
  EXPECT_EQ(info.pointCount, 518862u);
}

INSTANTIATE_TEST_SUITE_P(Ept, EptEncodings, ::testing::Values("binary", "zstandard", "laszip"));

// ---- hostile datasets ----------------------------------------------------------------------------------

// Opens, walks and reads every node; expects one InputError line with `words` in it.
void expectRefused(const fs::path& json, const std::string& words) {
  try {
    const auto source = openEpt(json);
    pointrast::lod::forEachNode(*source, [&](const NodeInfo& n) {
      source->readNode(n);
      return true;
    });
    ADD_FAILURE() << "expected an InputError about: " << words;
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(words), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  EXPECT_THROW(readCloud(json, quiet()), InputError);
}

struct Dataset {
  iotest::TempDir dir;
  fs::path json;
  explicit Dataset(const char* type) { json = iotest::writeEpt(data(kCopc), dir / "ept", type); }
  fs::path root() const { return json.parent_path(); }
  fs::path hierarchy(const std::string& key) const { return root() / "ept-hierarchy" / (key + ".json"); }
  fs::path node(const std::string& file) const { return root() / "ept-data" / file; }
  nlohmann::json load(const fs::path& p) const {
    auto bytes = iotest::readBytes(p);
    return nlohmann::json::parse(bytes.begin(), bytes.end());
  }
  void save(const fs::path& p, const nlohmann::json& j) const { iotest::writeText(p, j.dump()); }
  // The subtree file's key (the one -1 in the root file).
  std::string splitKey() const {
    const nlohmann::json root = load(hierarchy("0-0-0-0"));
    for (auto it = root.begin(); it != root.end(); ++it)
      if (*it == -1) return it.key();
    return "";
  }
};

TEST(EptHostile, MalformedEptJson) {
  Dataset d("binary");
  const nlohmann::json good = d.load(d.json);
  auto with = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& words) {
    nlohmann::json j = good;
    edit(j);
    d.save(d.json, j);
    expectRefused(d.json, words);
  };
  with([](auto& j) { j["dataType"] = "brotli"; }, "dataType \"brotli\" is unknown");
  with([](auto& j) { j.erase("schema"); }, "\"schema\"");
  with([](auto& j) { j["schema"][0]["type"] = "complex"; }, "has type \"complex\"");
  with([](auto& j) { j["schema"][0]["size"] = 3; }, "has size 3");
  with([](auto& j) { j["schema"].erase(1); }, "no Y dimension");
  with([](auto& j) { j["bounds"] = {1, 2, 3}; }, "\"bounds\" is not an array of 6 numbers");
  with(
      [](auto& j) {
        j["bounds"][0] = 1e300;
        j["bounds"][3] = -1e300;
      },
      "minimum above its maximum");
  with([](auto& j) { j["span"] = 0; }, "\"span\"");
  with([](auto& j) { j["points"] = -4; }, "\"points\"");
  with([](auto& j) { j["hierarchyType"] = "gzip"; }, "JSON hierarchies");
  iotest::writeText(d.json, "{\"bounds\": [1, 2");
  expectRefused(d.json, "ept.json");
  iotest::writeText(d.json, std::string(5000, '[') + std::string(5000, ']'));
  expectRefused(d.json, "nested more than");
}

TEST(EptHostile, MalformedHierarchies) {
  Dataset d("binary");
  const fs::path rootFile = d.hierarchy("0-0-0-0");
  const nlohmann::json good = d.load(rootFile);
  auto with = [&](const std::function<void(nlohmann::json&)>& edit, const std::string& words) {
    nlohmann::json j = good;
    edit(j);
    d.save(rootFile, j);
    expectRefused(d.json, words);
  };
  with([](auto& j) { j["1-0-0-7"] = 5; }, "not a node D-X-Y-Z"); // z beyond level 1's two cells
  with([](auto& j) { j["31-0-0-0"] = 5; }, "not a node D-X-Y-Z");
  with([](auto& j) { j["-1-0-0-0"] = 5; }, "not a node D-X-Y-Z");
  with([](auto& j) { j["1-0-0-0x"] = 5; }, "not a node D-X-Y-Z");
  with([](auto& j) { j["1-0-0-0"] = -3; }, "negative count");
  with([](auto& j) { j["1-0-0-0"] = 1.5; }, "fractional count");
  with([](auto& j) { j["1-0-0-0"] = "12"; }, "a string");
  with([](auto& j) { j["1-0-0-0"] = nlohmann::json::object({{"a", 1}}); }, "nested object");
  with([](auto& j) { j["1-0-0-0"] = {1, 2}; }, "an array");
  with([](auto& j) { j.erase("0-0-0-0"); }, "does not list the root node");
  iotest::writeText(rootFile, "{\"0-0-0-0\": 5, \"0-0-0-0\": 6}");
  expectRefused(d.json, "a second time");
  iotest::writeText(rootFile, "[1, 2");
  expectRefused(d.json, "0-0-0-0.json");
  d.save(rootFile, good);

  // The subtree file: a node outside its subtree, its own key missing, its own key as -1 again.
  const std::string split = d.splitKey();
  ASSERT_FALSE(split.empty());
  const nlohmann::json sub = d.load(d.hierarchy(split));
  nlohmann::json bad = sub;
  bad["0-0-0-0"] = 1;
  d.save(d.hierarchy(split), bad);
  expectRefused(d.json, "outside the subtree of " + split);
  bad = sub;
  bad.erase(split);
  d.save(d.hierarchy(split), bad);
  expectRefused(d.json, "does not list node " + split);
  bad = sub;
  bad[split] = -1;
  d.save(d.hierarchy(split), bad);
  expectRefused(d.json, "a second time");
  fs::remove(d.hierarchy(split));
  expectRefused(d.json, split + ".json");
}

TEST(EptHostile, CountsThatDisagreeWithTheData) {
  for (const char* type : {"binary", "zstandard", "laszip"}) {
    SCOPED_TRACE(type);
    Dataset d(type);
    const fs::path rootFile = d.hierarchy("0-0-0-0");
    nlohmann::json j = d.load(rootFile);
    const int64_t count = j["0-0-0-0"].get<int64_t>();
    j["0-0-0-0"] = count + 1;
    d.save(rootFile, j);
    const std::string words = std::string(type) == "binary"      ? "points of 26 bytes are"
                              : std::string(type) == "zstandard" ? "decompresses to"
                                                                 : "the hierarchy says";
    expectRefused(d.json, words);
    // Billions claimed: refused without allocating for them.
    j["0-0-0-0"] = int64_t(4) << 40;
    d.save(rootFile, j);
    expectRefused(d.json, std::string(type) == "laszip" ? "the hierarchy says" : "0-0-0-0.");
  }
}

TEST(EptHostile, DamagedNodeData) {
  {
    Dataset d("zstandard");
    auto bytes = iotest::readBytes(d.node("0-0-0-0.zst"));
    bytes.resize(bytes.size() / 2);
    iotest::writeBytes(d.node("0-0-0-0.zst"), bytes);
    expectRefused(d.json, "0-0-0-0.zst");
    iotest::writeText(d.node("0-0-0-0.zst"), "not zstd at all");
    expectRefused(d.json, "not valid zstd data");
  }
  {
    Dataset d("binary");
    fs::remove(d.node("0-0-0-0.bin"));
    expectRefused(d.json, "0-0-0-0.bin");
  }
  {
    Dataset d("laszip");
    auto bytes = iotest::readBytes(d.node("0-0-0-0.laz"));
    bytes.resize(bytes.size() - 40);
    iotest::writeBytes(d.node("0-0-0-0.laz"), bytes);
    expectRefused(d.json, "0-0-0-0.laz");
  }
}

} // namespace

namespace {

// A one-node dataset from a LAS file: unscaled double X/Y/Z (quantized on reading), 16-bit color.
TEST(Ept, FloatCoordinatesAndColor) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const PointCloud las = readCloud(data("las/autzen_trim.las"), quiet());
  iotest::TempDir dir;
  const fs::path root = dir / "ept";
  fs::create_directories(root / "ept-data");
  fs::create_directories(root / "ept-hierarchy");
  std::vector<uint8_t> bin;
  auto put = [&](const void* p, size_t n) {
    bin.insert(bin.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
  };
  for (uint64_t i = 0; i < las.size(); ++i) {
    const glm::dvec3 w = las.world(i);
    put(&w.x, 8);
    put(&w.y, 8);
    put(&w.z, 8);
    for (int c = 0; c < 3; ++c) {
      const uint16_t v = uint16_t(iotest::channel(las.colors[i], c) << 8); // 16-bit color
      put(&v, 2);
    }
  }
  iotest::writeBytes(root / "ept-data" / "0-0-0-0.bin", bin);
  iotest::writeText(root / "ept-hierarchy" / "0-0-0-0.json",
                    "{\"0-0-0-0\": " + std::to_string(las.size()) + "}");
  const double edge = std::max({las.bounds.size().x, las.bounds.size().y, las.bounds.size().z});
  nlohmann::json ept = {{"bounds",
                         {las.bounds.min.x, las.bounds.min.y, las.bounds.min.z, las.bounds.min.x + edge,
                          las.bounds.min.y + edge, las.bounds.min.z + edge}},
                        {"dataType", "binary"},
                        {"points", las.size()},
                        {"span", 256},
                        {"schema",
                         {{{"name", "X"}, {"type", "float"}, {"size", 8}},
                          {{"name", "Y"}, {"type", "float"}, {"size", 8}},
                          {{"name", "Z"}, {"type", "float"}, {"size", 8}},
                          {{"name", "Red"}, {"type", "unsigned"}, {"size", 2}},
                          {{"name", "Green"}, {"type", "unsigned"}, {"size", 2}},
                          {{"name", "Blue"}, {"type", "unsigned"}, {"size", 2}}}}};
  iotest::writeText(root / "ept.json", ept.dump());
  const PointCloud cloud = readCloud(root, quiet());
  ASSERT_EQ(cloud.size(), las.size());
  EXPECT_EQ(cloud.colors, las.colors); // 16-bit values, shifted back to the 8-bit originals
  EXPECT_TRUE(cloud.intensity.empty());
  for (uint64_t i = 0; i < cloud.size(); i += 37)
    for (int a = 0; a < 3; ++a)
      ASSERT_NEAR(cloud.world(i)[a], las.world(i)[a], cloud.scale[a]) << i;
  const FileInfo info = probeFile(root / "ept.json");
  EXPECT_TRUE(info.hasColor);
  EXPECT_EQ(info.colorBits, 16);
}

} // namespace

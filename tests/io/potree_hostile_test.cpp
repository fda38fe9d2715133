// Hostile Potree 2.0 octrees: every prefix of each of the three files, flipped hierarchy bytes,
// metadata.json with fields missing or of the wrong kind, byte ranges past the end, proxies pointing into
// their own chunk or sharing one (cycles), counts that lie, absurd depth. Each read must either succeed
// or throw one InputError line naming the octree: no crash, hang or huge allocation (run under
// AddressSanitizer, whose allocator refuses absurd sizes).
#include <fstream>
#include <functional>

#include "io/potree_test_util.h"

using namespace pointrast;
using namespace pointrast::io;
using iotest::Outcome;
using potreetest::makeTree;
using potreetest::patchRecord;
using potreetest::Tree;
using potreetest::writeTree;

namespace {

// Opens the octree, walks every node and reads its points; then readCloud and probeFile.
Outcome readOctree(const std::filesystem::path& dir, std::string* message = nullptr) {
  Outcome outcome = Outcome::Read;
  try {
    std::unique_ptr<lod::NodeSource> source = openPotree(dir);
    lod::forEachNode(*source, [&](const lod::NodeInfo& node) {
      EXPECT_LE(source->readNode(node).size(), node.pointCount);
      source->nodeBytes(node);
      return true;
    });
  } catch (const InputError& e) {
    outcome = Outcome::Refused;
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind(dir.string(), 0), 0u) << "names the octree: " << what;
    if (message) *message = what;
  } catch (const std::exception& e) {
    ADD_FAILURE() << dir << ": threw a non-InputError: " << e.what();
  }
  EXPECT_EQ(iotest::readOrRefuse(dir), outcome) << dir;
  return outcome;
}

// The three files of a small octree with proxies (chunks of one level).
struct Files {
  std::vector<uint8_t> metadata, hierarchy, octree;
};
Files smallOctree(PotreeEncoding encoding, uint64_t points = 120, int depth = 3) {
  iotest::TempDir dir;
  PotreeWriteOptions o;
  o.encoding = encoding;
  o.hierarchyStepSize = 1;
  writeTree(makeTree({.points = points, .depth = depth}), dir / "o", o);
  return {iotest::readBytes(dir / "o" / "metadata.json"), iotest::readBytes(dir / "o" / "hierarchy.bin"),
          iotest::readBytes(dir / "o" / "octree.bin")};
}
void put(const std::filesystem::path& dir, const Files& f) {
  std::filesystem::create_directories(dir);
  iotest::writeBytes(dir / "metadata.json", f.metadata);
  iotest::writeBytes(dir / "hierarchy.bin", f.hierarchy);
  iotest::writeBytes(dir / "octree.bin", f.octree);
}
const char* fileName(std::vector<uint8_t> Files::*member) {
  return member == &Files::metadata    ? "metadata.json"
         : member == &Files::hierarchy ? "hierarchy.bin"
                                       : "octree.bin";
}

// Every prefix of one file of the octree must be refused (up to `end`: by default the whole file); the
// whole file must read.
void sweepPrefixes(const Files& files, std::vector<uint8_t> Files::*member, size_t stride = 1,
                   size_t end = SIZE_MAX) {
  iotest::TempDir dir;
  put(dir / "o", files);
  const std::vector<uint8_t>& whole = files.*member;
  for (size_t len = 0; len < std::min(end, whole.size()); len += stride) {
    iotest::writeBytes(dir / "o" / fileName(member), whole.data(), len);
    EXPECT_EQ(readOctree(dir / "o"), Outcome::Refused) << "prefix " << len;
    if (::testing::Test::HasFailure()) return;
  }
  put(dir / "o", files);
  EXPECT_EQ(readOctree(dir / "o"), Outcome::Read);
}

TEST(PotreeHostile, TruncatedFilesAreRefused) {
  for (PotreeEncoding encoding : {PotreeEncoding::Default, PotreeEncoding::Brotli}) {
    const Files files = smallOctree(encoding, 40, 2);
    sweepPrefixes(files, &Files::hierarchy);
    sweepPrefixes(files, &Files::octree, encoding == PotreeEncoding::Default ? 3 : 1);
    // metadata.json ends with a newline, without which it is still whole.
    sweepPrefixes(files, &Files::metadata, 3, files.metadata.size() - 1);
  }
}

TEST(PotreeHostile, FlippedHierarchyBytes) {
  for (PotreeEncoding encoding : {PotreeEncoding::Default, PotreeEncoding::Brotli}) {
    const Files files = smallOctree(encoding, 40, 2);
    iotest::TempDir dir;
    put(dir / "o", files);
    Files f = files;
    for (size_t i = 0; i < files.hierarchy.size(); ++i) {
      for (uint8_t v : {uint8_t(0x00), uint8_t(0xFF), uint8_t(files.hierarchy[i] ^ 0x01),
                        uint8_t(files.hierarchy[i] ^ 0x80)}) {
        f.hierarchy[i] = v;
        iotest::writeBytes(dir / "o" / "hierarchy.bin", f.hierarchy);
        readOctree(dir / "o");
      }
      f.hierarchy[i] = files.hierarchy[i];
      if (::testing::Test::HasFailure()) return;
    }
  }
}

TEST(PotreeHostile, FlippedNodeBytes) {
  // Brotli streams and DEFAULT records with any byte changed: refused or read, never more points.
  for (PotreeEncoding encoding : {PotreeEncoding::Default, PotreeEncoding::Brotli}) {
    const Files files = smallOctree(encoding, 40, 2);
    iotest::TempDir dir;
    put(dir / "o", files);
    Files f = files;
    for (size_t i = 0; i < files.octree.size(); i += encoding == PotreeEncoding::Default ? 5 : 1) {
      for (uint8_t v : {uint8_t(0x00), uint8_t(0xFF), uint8_t(files.octree[i] ^ 0x04)}) {
        f.octree[i] = v;
        iotest::writeBytes(dir / "o" / "octree.bin", f.octree);
        readOctree(dir / "o");
      }
      f.octree[i] = files.octree[i];
      if (::testing::Test::HasFailure()) return;
    }
  }
}

// ---- metadata.json -----------------------------------------------------------------------------------

nlohmann::json parse(const std::vector<uint8_t>& bytes) {
  return nlohmann::json::parse(bytes.begin(), bytes.end());
}
std::vector<uint8_t> dump(const nlohmann::json& j) {
  const std::string s = j.dump();
  return {s.begin(), s.end()};
}

// Calls visit(pointer) for every value of the document (objects' members, arrays' elements).
void forEachValue(const nlohmann::json& j, const nlohmann::json::json_pointer& at,
                  const std::function<void(const nlohmann::json::json_pointer&)>& visit) {
  if (j.is_object())
    for (const auto& [key, value] : j.items()) {
      visit(at / key);
      forEachValue(value, at / key, visit);
    }
  if (j.is_array())
    for (size_t i = 0; i < j.size(); ++i) {
      visit(at / i);
      forEachValue(j[i], at / i, visit);
    }
}

TEST(PotreeHostile, MetadataFieldsMissingOrWrong) {
  for (PotreeEncoding encoding : {PotreeEncoding::Default, PotreeEncoding::Brotli}) {
    const Files files = smallOctree(encoding, 40, 2);
    const nlohmann::json meta = parse(files.metadata);
    iotest::TempDir dir;
    put(dir / "o", files);
    Files f = files;
    const std::vector<nlohmann::json> wrong = {
        nullptr, "x",         -1, 0, 1.5, 1e300, nlohmann::json::array(), nlohmann::json::object(),
        true,    4294967296.0};
    forEachValue(meta, nlohmann::json::json_pointer(), [&](const nlohmann::json::json_pointer& at) {
      nlohmann::json removed = meta;
      nlohmann::json& parent = removed[at.parent_pointer()];
      if (parent.is_object())
        parent.erase(at.back());
      else
        parent.erase(std::stoul(at.back()));
      f.metadata = dump(removed);
      iotest::writeBytes(dir / "o" / "metadata.json", f.metadata);
      readOctree(dir / "o");
      for (const nlohmann::json& value : wrong) {
        nlohmann::json changed = meta;
        changed[at] = value;
        f.metadata = dump(changed);
        iotest::writeBytes(dir / "o" / "metadata.json", f.metadata);
        readOctree(dir / "o");
      }
    });
    // The fields the reader needs: each missing one is refused, with its name.
    for (const char* field :
         {"version", "points", "hierarchy", "offset", "scale", "spacing", "boundingBox", "attributes"}) {
      nlohmann::json removed = meta;
      removed.erase(field);
      f.metadata = dump(removed);
      iotest::writeBytes(dir / "o" / "metadata.json", f.metadata);
      std::string message;
      EXPECT_EQ(readOctree(dir / "o", &message), Outcome::Refused) << field;
      EXPECT_NE(message.find("metadata.json"), std::string::npos) << message;
    }
    for (const char* text : {"", "{", "[]", "{\"version\": \"2.0\"}", "{\"version\": \"1.8\"}", "null"}) {
      f.metadata.assign(text, text + std::strlen(text));
      iotest::writeBytes(dir / "o" / "metadata.json", f.metadata);
      EXPECT_EQ(readOctree(dir / "o"), Outcome::Refused) << text;
    }
  }
}

TEST(PotreeHostile, MetadataWithAbsurdValues) {
  const Files files = smallOctree(PotreeEncoding::Default);
  iotest::TempDir dir;
  auto refused = [&](const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json meta = parse(files.metadata);
    edit(meta);
    Files f = files;
    f.metadata = dump(meta);
    put(dir / "o", f);
    std::string message;
    EXPECT_EQ(readOctree(dir / "o", &message), Outcome::Refused) << meta.dump();
    return message;
  };
  EXPECT_NE(refused([](nlohmann::json& m) { m["hierarchy"]["depth"] = 31; }).find("depth"),
            std::string::npos);
  refused([](nlohmann::json& m) { m["hierarchy"]["firstChunkSize"] = 23; });
  refused([](nlohmann::json& m) { m["hierarchy"]["firstChunkSize"] = 22 * 1000; });
  refused([](nlohmann::json& m) { m["hierarchy"]["stepSize"] = 0; });
  refused([](nlohmann::json& m) { m["scale"] = {0.001, 0, 0.001}; });
  refused(
      [](nlohmann::json& m) { m["boundingBox"]["max"][1] = m["boundingBox"]["max"][1].get<double>() + 5; });
  refused([](nlohmann::json& m) { m["encoding"] = "LAZ"; });
  refused([](nlohmann::json& m) { m["attributes"].erase(0); }); // no position
  refused([](nlohmann::json& m) { m["attributes"][0]["type"] = "int16"; });
  refused([](nlohmann::json& m) { m["attributes"][1]["size"] = 100000; });
  refused([](nlohmann::json& m) {
    for (int i = 0; i < 2000; ++i)
      m["attributes"].push_back(m["attributes"][1]);
  });
  // An unknown extra attribute changes the stride: the nodes' byte sizes no longer match their counts.
  refused([](nlohmann::json& m) {
    m["attributes"].push_back(
        {{"name", "gps-time"}, {"size", 8}, {"numElements", 1}, {"elementSize", 8}, {"type", "double"}});
  });
  // A metadata.json far larger than any octree's is not read at all.
  Files f = files;
  put(dir / "o", f);
  std::filesystem::resize_file(dir / "o" / "metadata.json", uint64_t(64) << 20);
  EXPECT_EQ(readOctree(dir / "o"), Outcome::Refused);
}

// ---- hierarchy records that lie ------------------------------------------------------------------------

class HostileRecords : public ::testing::TestWithParam<PotreeEncoding> {
protected:
  void SetUp() override {
    PotreeWriteOptions o;
    o.encoding = GetParam();
    o.hierarchyStepSize = 1;
    tree_ = makeTree({.points = 400, .depth = 3});
    writeTree(tree_, dir_ / "o", o);
    for (const auto& [key, records] : tree_.nodes)
      if (key.level == 2 && !records.empty()) withPoints_ = key;
    for (const potreetest::DiskNode& n : potreetest::walkHierarchy(dir_ / "o"))
      if (n.record.type == potree::kProxy) proxies_.push_back(n);
    ASSERT_EQ(withPoints_.level, 2);
    ASSERT_GE(proxies_.size(), 2u);
  }
  std::string refused() {
    std::string message;
    EXPECT_EQ(readOctree(dir_ / "o", &message), Outcome::Refused);
    return message;
  }
  iotest::TempDir dir_;
  Tree tree_;
  lod::NodeKey withPoints_;                   // a node of level 2 with points
  std::vector<potreetest::DiskNode> proxies_; // proxy records
};

TEST_P(HostileRecords, ByteRangePastTheEnd) {
  const uint64_t size = std::filesystem::file_size(dir_ / "o" / "octree.bin");
  patchRecord(dir_ / "o", withPoints_, false, [&](potree::Record& r) { r.byteOffset = int64_t(size); });
  EXPECT_NE(refused().find("of octree.bin, which holds"), std::string::npos);
}

TEST_P(HostileRecords, NegativeAndHugeRanges) {
  patchRecord(dir_ / "o", withPoints_, false, [](potree::Record& r) { r.byteOffset = -8; });
  refused();
  patchRecord(dir_ / "o", withPoints_, false, [](potree::Record& r) {
    r.byteOffset = 8;
    r.byteSize = INT64_MAX;
  });
  refused();
}

TEST_P(HostileRecords, ProxyPointingIntoItsOwnChunk) {
  const std::vector<uint8_t> original = iotest::readBytes(dir_ / "o" / "hierarchy.bin");
  // Into the first chunk (the root's).
  patchRecord(dir_ / "o", proxies_[0].key, true, [](potree::Record& r) { r.byteOffset = 0; });
  EXPECT_NE(refused().find("cycle"), std::string::npos);
  // A deeper proxy into the chunk that holds it.
  iotest::writeBytes(dir_ / "o" / "hierarchy.bin", original);
  const potreetest::DiskNode& deep = proxies_.back();
  ASSERT_GT(deep.chunk, 0u);
  patchRecord(dir_ / "o", deep.key, true, [&](potree::Record& r) { r.byteOffset = int64_t(deep.chunk); });
  EXPECT_NE(refused().find("cycle"), std::string::npos);
}

TEST_P(HostileRecords, TwoProxiesSharingAChunk) {
  const potree::Record target = proxies_[0].record;
  patchRecord(dir_ / "o", proxies_[1].key, true, [&](potree::Record& r) {
    r.byteOffset = target.byteOffset;
    r.byteSize = target.byteSize;
  });
  refused();
}

TEST_P(HostileRecords, ProxyRangeOutsideTheFile) {
  const std::vector<uint8_t> original = iotest::readBytes(dir_ / "o" / "hierarchy.bin");
  patchRecord(dir_ / "o", proxies_[0].key, true, [](potree::Record& r) { r.byteSize = 22 * 100000; });
  refused();
  iotest::writeBytes(dir_ / "o" / "hierarchy.bin", original);
  patchRecord(dir_ / "o", proxies_[0].key, true, [](potree::Record& r) { r.byteSize = 21; });
  refused();
}

TEST_P(HostileRecords, CountsThatLie) {
  const lod::NodeKey key = withPoints_;
  for (uint32_t count : {uint32_t(tree_.nodes.at(key).size() + 1), uint32_t(tree_.nodes.at(key).size() - 1),
                         uint32_t(1) << 20, UINT32_MAX}) {
    patchRecord(dir_ / "o", key, false, [&](potree::Record& r) { r.pointCount = count; });
    refused();
  }
}

TEST_P(HostileRecords, ChildMaskThatLies) {
  // A mask with more children than the chunk holds records for, or fewer.
  patchRecord(dir_ / "o", lod::NodeKey{}, false, [](potree::Record& r) { r.childMask ^= 0x01; });
  refused();
}

INSTANTIATE_TEST_SUITE_P(Encodings, HostileRecords,
                         ::testing::Values(PotreeEncoding::Default, PotreeEncoding::Brotli));

// A hand-made chain of chunks, each one node whose only child is a proxy for the next: deeper than any
// octree may be.
TEST(PotreeHostile, AbsurdDepthIsRefused) {
  iotest::TempDir dir;
  const Files files = smallOctree(PotreeEncoding::Default);
  nlohmann::json meta = parse(files.metadata);
  meta["hierarchy"]["firstChunkSize"] = 44;
  Files f = files;
  f.metadata = dump(meta);
  f.octree.clear();
  const int chunks = 40;
  f.hierarchy.assign(size_t(chunks) * 44, 0);
  for (int c = 0; c < chunks; ++c) {
    potree::Record node;
    node.type = potree::kNormal;
    node.childMask = 0x01;
    potree::Record proxy;
    proxy.type = potree::kProxy;
    proxy.byteOffset = 44 * (c + 1);
    proxy.byteSize = c + 1 < chunks ? 44 : 22;
    potree::storeRecord(f.hierarchy.data() + 44 * c, node);
    potree::storeRecord(f.hierarchy.data() + 44 * c + 22, proxy);
  }
  put(dir / "o", f);
  std::string message;
  EXPECT_EQ(readOctree(dir / "o", &message), Outcome::Refused);
  EXPECT_NE(message.find("30 levels"), std::string::npos) << message;
}

TEST(PotreeHostile, MissingFilesAndOtherPaths) {
  iotest::TempDir dir;
  const Files files = smallOctree(PotreeEncoding::Brotli);
  for (const char* missing : {"hierarchy.bin", "octree.bin"}) {
    put(dir / "o", files);
    std::filesystem::remove(dir / "o" / missing);
    std::string message;
    EXPECT_EQ(readOctree(dir / "o", &message), Outcome::Refused);
    EXPECT_NE(message.find(missing), std::string::npos) << message;
  }
  put(dir / "o", files);
  std::filesystem::remove(dir / "o" / "hierarchy.bin");
  std::filesystem::create_directory(dir / "o" / "hierarchy.bin");
  EXPECT_EQ(readOctree(dir / "o"), Outcome::Refused);
}

} // namespace

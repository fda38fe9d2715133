// Truncated compressed files through the streaming and level-of-detail paths (the octree builder's
// PointSource, the COPC NodeSource), which the whole-file prefix sweeps of hostile_input_test.cpp do not
// take. Each prefix is opened and read to the end or refused with InputError; run under AddressSanitizer
// in the sanitized build, so an overread fails too.
#include <functional>
#include <vector>

#include "io/copc_ept/copc.h"
#include "io/io_test_util.h"
#include "io/point_source.h"

using iotest::data;
using iotest::Outcome;
using pointrast::InputError;
using pointrast::PointRecord;

namespace {

// Writes prefixes [0, size) of bytes, at step 1 from denseBegin on and at stride before it, and gives each
// to open; every prefix must be refused with InputError when prefixesMustFail, and the whole file read.
void sweep(const std::vector<uint8_t>& bytes, const char* name, size_t denseBegin, size_t stride,
           bool prefixesMustFail, const std::function<void(const std::filesystem::path&)>& open) {
  iotest::TempDir dir;
  const auto path = dir / name;
  auto outcome = [&](size_t len) {
    iotest::writeBytes(path, bytes.data(), len);
    try {
      open(path);
      return Outcome::Read;
    } catch (const InputError&) {
      return Outcome::Refused;
    }
  };
  for (size_t len = 0; len < bytes.size(); len += len < denseBegin ? stride : 1) {
    const Outcome o = outcome(len);
    if (prefixesMustFail) {
      EXPECT_EQ(o, Outcome::Refused) << name << " prefix " << len;
    }
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_EQ(outcome(bytes.size()), Outcome::Read) << name << " in full";
}

// Every piece of the source, each checked to hold the count it claims.
void readEveryPiece(const std::filesystem::path& path) {
  auto source = pointrast::io::openPointSource(path);
  std::vector<PointRecord> records;
  uint64_t total = 0;
  for (size_t i = 0; i < source->pieces().size(); ++i) {
    source->readPiece(i, records);
    ASSERT_EQ(records.size(), source->pieces()[i].count);
    total += records.size();
  }
  EXPECT_EQ(total, source->info().pointCount);
}

// The hierarchy walked from the root, every node read and checked against its stated count.
void readEveryNode(const std::filesystem::path& path) {
  auto source = pointrast::io::openCopc(path);
  std::vector<pointrast::lod::NodeInfo> pending = {source->root()};
  while (!pending.empty()) {
    const pointrast::lod::NodeInfo node = pending.back();
    pending.pop_back();
    EXPECT_EQ(source->readNode(node).size(), node.pointCount);
    for (const auto& child : source->children(node))
      pending.push_back(child);
  }
}

TEST(TruncationSweep, LazPiecesAreReadOrRefused) {
  POINTRAST_REQUIRE_DATA("laz/simple.laz");
  // A prefix cuts the chunk table (written last): open refuses it, or a piece is refused when it is read.
  const auto bytes = iotest::readBytes(data("laz/simple.laz"));
  sweep(bytes, "t.laz", bytes.size() - 600, 37, false, readEveryPiece);
}

TEST(TruncationSweep, CopcNodesAreReadOrRefused) {
  POINTRAST_REQUIRE_DATA("laz/lone-star.copc.laz");
  // The hierarchy page sits in the EVLR at the end: every prefix loses part of it and must be refused
  // when opened, before any node is read. Dense over the EVLR and the last chunk, strided before.
  const auto bytes = iotest::readBytes(data("laz/lone-star.copc.laz"));
  sweep(bytes, "t.copc.laz", bytes.size() - 1200, 4099, true, readEveryNode);
}

} // namespace

// Hostile LAZ files: chunk tables pointing past the end or backwards, counts that lie, corrupt coded
// bytes. Each must read or give one InputError naming the file: no crash, no hang, no allocation beyond
// what the data codes (run under AddressSanitizer, which fails on allocations of the claimed sizes).
#include "io/io_test_util.h"
#include "io/las/las_format.h"
#include "io/las/laz_compose.h"
#include "io/las/laz_format.h"
#include "io/las/laz_reader.h"

using pointrast::InputError;
using namespace pointrast::io;
using iotest::data;
using iotest::Outcome;
using iotest::quiet;
using iotest::readOrRefuse;

namespace {

struct LazBytes {
  std::vector<uint8_t> bytes;
  uint32_t pointOffset = 0;
  uint64_t tableOffset = 0;
};

LazBytes load(std::vector<uint8_t> bytes) {
  LazBytes f;
  f.bytes = std::move(bytes);
  std::memcpy(&f.pointOffset, f.bytes.data() + 96, 4);
  int64_t table;
  std::memcpy(&table, f.bytes.data() + f.pointOffset, 8);
  f.tableOffset = uint64_t(table);
  return f;
}

// 212 + 318 points in layered chunks (POINT14), about 4 KB.
LazBytes smallLayered() {
  return load(composeLaz(data("laz/lone-star.copc.laz"), {0, 9}));
}
LazBytes smallPointwise() {
  return load(iotest::readBytes(data("laz/simple.laz")));
}

template <class T> void put(std::vector<uint8_t>& b, size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof v);
}

// Writes bytes and expects one InputError line naming the file, with `words` in it.
void expectRefused(const std::vector<uint8_t>& bytes, const std::string& words) {
  iotest::TempDir dir;
  const auto path = dir / "hostile.laz";
  iotest::writeBytes(path, bytes);
  std::string message;
  ASSERT_EQ(readOrRefuse(path, &message), Outcome::Refused) << words;
  EXPECT_NE(message.find("hostile.laz"), std::string::npos) << message;
  EXPECT_NE(message.find(words), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// Replaces the chunk table with one encoding `chunks` and patches the header's point count to `total`.
std::vector<uint8_t> withTable(const LazBytes& f, const std::vector<laz::Chunk>& chunks, uint64_t total) {
  std::vector<uint8_t> b(f.bytes.begin(), f.bytes.begin() + static_cast<ptrdiff_t>(f.tableOffset));
  const std::vector<uint8_t> table = laz::encodeChunkTable(chunks, true);
  b.insert(b.end(), table.begin(), table.end());
  put<uint64_t>(b, 247, total); // LAS 1.4 64-bit count (the composed files are LAS 1.4)
  return b;
}

TEST(LazHostile, ComposedFilesDecodeLikeTheirSource) {
  POINTRAST_REQUIRE_DATA("laz/autzen_trim.laz");
  const std::vector<uint8_t> all = readLazRecords(data("laz/autzen_trim.laz"));
  iotest::TempDir dir;
  iotest::writeBytes(dir / "c.laz", composeLaz(data("laz/autzen_trim.laz"), {0, 1, 2}));
  EXPECT_EQ(readLazRecords(dir / "c.laz"), all);
  // Chunks in another order and repeated: the records of those chunks in that order.
  iotest::writeBytes(dir / "r.laz", composeLaz(data("laz/autzen_trim.laz"), {2, 0, 2}));
  const std::vector<uint8_t> r = readLazRecords(dir / "r.laz");
  const size_t chunk = 50000 * 34, last = 10000 * 34;
  ASSERT_EQ(r.size(), 2 * last + chunk);
  EXPECT_TRUE(std::equal(r.begin(), r.begin() + last, all.begin() + 2 * chunk));
  EXPECT_TRUE(std::equal(r.begin() + last, r.begin() + last + chunk, all.begin()));
  EXPECT_EQ(readCloud(dir / "r.laz", quiet()).size(), 70000u);
}

TEST(LazHostile, ChunkTableEncoderMatchesLaszipByteForByte) {
  POINTRAST_REQUIRE_DATA();
  // The tables LASzip and laz-perf wrote, re-encoded from their decoded entries.
  for (const char* file : {"laz/autzen_trim.laz", "laz/las_with_several_extra_byte_bloc.laz",
                           "laz/lone-star.copc.laz", "laz/simple.laz"}) {
    SCOPED_TRACE(file);
    detail::InputFile in(data(file));
    const laz::LazFile laz = laz::openLaz(in);
    const std::vector<uint8_t> encoded = laz::encodeChunkTable(laz.chunks, laz.layout.variableChunks());
    std::vector<uint8_t> stored(encoded.size());
    in.readAt(laz.chunkTableOffset, stored.data(), stored.size());
    EXPECT_EQ(encoded, stored);
  }
}

TEST(LazHostile, ChunkTableOffsetPastTheEndOrBackwards) {
  POINTRAST_REQUIRE_DATA();
  for (const LazBytes& f : {smallPointwise(), smallLayered()}) {
    std::vector<uint8_t> b = f.bytes;
    put<int64_t>(b, f.pointOffset, int64_t(b.size()) + 100);
    expectRefused(b, "past the end");
    put<int64_t>(b, f.pointOffset, 12);
    expectRefused(b, "before the point data");
    put<int64_t>(b, f.pointOffset, -5);
    expectRefused(b, "before the point data");
    put<int64_t>(b, f.pointOffset, int64_t(f.pointOffset)); // "table right here": the writer died
    expectRefused(b, "missing");
    // -1: the offset is in the last 8 bytes of the file, which here hold no offset.
    put<int64_t>(b, f.pointOffset, -1);
    expectRefused(b, "chunk table");
    b = f.bytes;
    put<uint32_t>(b, f.tableOffset, 1);
    expectRefused(b, "version 1");
    b = f.bytes;
    put<uint32_t>(b, f.tableOffset + 4, 0xFFFFFFFFu);
    expectRefused(b, "claims 4294967295 chunks");
  }
}

TEST(LazHostile, CountsThatLie) {
  POINTRAST_REQUIRE_DATA();
  const LazBytes f = smallLayered();
  // Chunk counts far above what the data codes: the decoder runs out of bytes and says so, having
  // grown its buffer with the points it really decoded, not the 4 billion claimed.
  expectRefused(withTable(f, {{0, 1438, 0, 4000000000u}, {0, 1733, 0, 318}}, 4000000318u), "damaged");
  // The chunk's own count (in its layer header) disagrees with the table.
  expectRefused(withTable(f, {{0, 1438, 0, 213}, {0, 1733, 0, 318}}, 531), "it counts 212 points itself");
  // Table and header disagree.
  expectRefused(withTable(f, {{0, 1438, 0, 212}, {0, 1733, 0, 318}}, 600), "the header says 600");
  // Chunk sizes: larger than the space before the table, or summing past it.
  expectRefused(withTable(f, {{0, 1438, 0, 212}, {0, 1000000, 0, 318}}, 530), "runs past the chunk table");
  expectRefused(withTable(f, {{0, 0xFFFFFFFFu, 0, 212}, {0, 1733, 0, 318}}, 530),
                "runs past the chunk table");
  // A chunk of no points.
  expectRefused(withTable(f, {{0, 1438, 0, 0}, {0, 1733, 0, 318}}, 318), "holds no points");
  // Sizes that split the data in the wrong place: the first chunk loses its end, the second its start.
  std::string message;
  iotest::TempDir dir;
  iotest::writeBytes(dir / "s.laz", withTable(f, {{0, 1000, 0, 212}, {0, 2171, 0, 318}}, 530));
  EXPECT_EQ(readOrRefuse(dir / "s.laz", &message), Outcome::Refused);

  // Pointwise, fixed chunks: the header claims more points than the chunk holds.
  LazBytes p = smallPointwise();
  std::vector<uint8_t> b = p.bytes;
  put<uint32_t>(b, 107, 40000);
  expectRefused(b, "ends before its last point");
  put<uint32_t>(b, 107, 4000000000u); // more than one chunk of 50,000 can hold
  expectRefused(b, "holds 50000 points in 1 chunks, the header says 4000000000");
}

// A run of records decodes only the chunks that hold it: with the second chunk's own count damaged, the
// first chunk's records read, and any run that reaches into the second chunk is refused.
TEST(LazHostile, ARangeDecodesOnlyTheChunksThatHoldIt) {
  POINTRAST_REQUIRE_DATA();
  const LazBytes f = smallLayered(); // chunks of 212 and 318 points, 1438 and 1733 bytes
  std::vector<uint8_t> b = f.bytes;
  uint16_t recordLength;
  std::memcpy(&recordLength, b.data() + 105, 2);
  const size_t second = f.pointOffset + 8 + 1438;
  put<uint32_t>(b, second + recordLength, 999); // the second chunk's own count
  iotest::TempDir dir;
  const auto path = dir / "second-damaged.laz";
  iotest::writeBytes(path, b);
  EXPECT_EQ(readLazRange(path, quiet(), 0, 212, nullptr).size(), 212u);
  EXPECT_EQ(readLazRange(path, quiet(), 100, 112, nullptr).size(), 112u);
  EXPECT_THROW(readLazRange(path, quiet(), 200, 13, nullptr), InputError);
  EXPECT_THROW(readLazRange(path, quiet(), 212, 1, nullptr), InputError);
  EXPECT_THROW(readCloud(path, quiet()), InputError);
}

TEST(LazHostile, CorruptCodedBytesReadOrRefuse) {
  POINTRAST_REQUIRE_DATA();
  iotest::TempDir dir;
  const auto path = dir / "c.laz";
  iotest::Lcg rng(77);
  for (const LazBytes& f : {smallPointwise(), smallLayered()}) {
    const size_t begin = f.pointOffset + 8, end = f.tableOffset;
    size_t refused = 0, tries = 0;
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<uint8_t> b = f.bytes;
      // One to four bytes changed anywhere in the chunks, including raw first points and layer sizes.
      for (int k = 0, n = 1 + int(rng.next() % 4); k < n; ++k)
        b[begin + rng.next() % (end - begin)] ^= static_cast<uint8_t>(1 + rng.next() % 255);
      iotest::writeBytes(path, b);
      refused += readOrRefuse(path) == Outcome::Refused;
      ++tries;
      if (::testing::Test::HasFailure()) return;
    }
    // Most damage changes values silently (the format has no checksums), some is caught.
    EXPECT_GT(refused, 0u);
    EXPECT_LE(refused, tries);
  }
}

TEST(LazHostile, LaszipVlrFlips) {
  POINTRAST_REQUIRE_DATA("laz/lone-star.copc.laz");
  iotest::TempDir dir;
  const auto path = dir / "v.laz";
  const LazBytes f = smallLayered();
  detail::InputFile in(data("laz/lone-star.copc.laz"));
  // The composed file keeps the LASzip VLR first among the VLRs after dropping COPC's.
  const size_t payload = 375 + 54;
  const std::vector<uint8_t> values = {0x00, 0xFF, 0x01, 0x03, 0x0E};
  for (size_t i = payload; i < payload + 40; ++i) {
    for (uint8_t v : values) {
      std::vector<uint8_t> b = f.bytes;
      b[i] = v;
      iotest::writeBytes(path, b);
      readOrRefuse(path);
      if (::testing::Test::HasFailure()) return;
    }
  }
}

} // namespace

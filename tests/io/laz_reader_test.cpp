// LAZ decoding against the LAS twins and record hashes in shared/data (README: "decodes to exactly").
#include "io/io_test_util.h"
#include "io/las_format.h"
#include "io/laz_reader.h"
#include "io/sha256.h"

using pointrast::InputError;
using pointrast::PointCloud;
using namespace pointrast::io;
using iotest::data;
using iotest::quiet;

namespace {

// The point records of an uncompressed LAS file, as bytes.
std::vector<uint8_t> lasRecords(const std::string& file) {
  detail::InputFile in(data(file));
  const detail::LasHeader hd = detail::readLasHeader(in);
  std::vector<uint8_t> bytes(hd.pointCount * hd.recordLength);
  in.readAt(hd.pointOffset, bytes.data(), bytes.size());
  return bytes;
}

struct Twin {
  const char* laz;
  const char* las;
  uint64_t points;
  const char* sha256; // of all decoded records (shared/data/README.md)
};

const Twin kTwins[] = {
    {"laz/simple.laz", "las/1.2-with-color.las", 1065,
     "0717948a72e6bf719db8d96ded1e76b760d73fb683347ebe3dd603832e3d5015"},
    {"laz/autzen_trim.laz", "las/autzen_trim.las", 110000,
     "f4eb6d80bf1fa507ffdcdaa73606d09041982659a50ee3895957e0b2b347f54b"},
    {"laz/lone-star.copc.laz", "las/lone-star.copc.las", 518862,
     "fb81e03fca9a6e3569feb6aa6e9eb92ddbca58ac10cb29fc8ba5e7eec4027dd3"},
    {"laz/las_with_several_extra_byte_bloc.laz", "las/las_with_several_extra_byte_bloc.las", 697721,
     "c19b99bc99062598ede4bed3bc6648832211f51b80ac22c8095cb547d8836406"},
};

TEST(LazReader, DecodesToTheRecordsOfTheLasTwin) {
  for (const Twin& t : kTwins) {
    SCOPED_TRACE(t.laz);
    const std::vector<uint8_t> decoded = readLazRecords(data(t.laz));
    const std::vector<uint8_t> twin = lasRecords(t.las);
    ASSERT_GE(decoded.size(), twin.size());
    // Full twins compare every record, prefix twins (PF8, COPC) their first 100,000.
    EXPECT_TRUE(std::equal(twin.begin(), twin.end(), decoded.begin())) << "records differ from " << t.las;
    EXPECT_EQ(iotest::sha256Hex(decoded), t.sha256);
    EXPECT_EQ(decoded.size() % t.points, 0u);
  }
}

} // namespace

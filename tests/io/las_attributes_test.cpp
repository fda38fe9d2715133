// LAS attributes beyond PointRecord's through the compact tail: a record packed and unpacked into its own
// format comes back byte for byte (random records of every format, and the records of real files), and
// across formats 1 <-> 6 the values survive.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "io/io_util.h"
#include "io/las/las_attributes.h"
#include "io/las/las_format.h"
#include "io/las/las_records.h"
#include "test_data.h"

namespace pointrast::io::detail {
namespace {

// The wave packet fields (formats 4, 5, 9, 10: 29 bytes from this offset) are not carried.
int wavePacketOffset(int f) {
  switch (f) {
  case 4:
    return 28;
  case 5:
    return 34;
  case 9:
    return 30;
  case 10:
    return 38;
  default:
    return -1;
  }
}

// A record of pointFormat holding only PointRecord's fields, as the LAS record writer lays them out.
std::vector<uint8_t> recordOf(const PointRecord& p, int f, size_t length) {
  std::vector<uint8_t> r(length, 0);
  storeLE<int32_t>(r.data(), p.x);
  storeLE<int32_t>(r.data() + 4, p.y);
  storeLE<int32_t>(r.data() + 8, p.z);
  storeLE<uint16_t>(r.data() + 12, p.intensity);
  if (las::isExtended(f)) {
    r[14] = p.returnNumber & 0x0F;
    r[16] = p.classification;
    storeLE<uint16_t>(r.data() + 20, p.pointSourceId);
  } else {
    r[14] = p.returnNumber & 0x07;
    r[15] = p.classification & 0x1F;
    storeLE<uint16_t>(r.data() + 18, p.pointSourceId);
  }
  if (const int rgb = las::kRgbOffset[size_t(f)]; rgb >= 0)
    for (int c = 0; c < 3; ++c)
      storeLE<uint16_t>(r.data() + rgb + 2 * c, p.rgb[c]);
  return r;
}

// Packs a record's attributes and rebuilds it from its PointRecord and the tail.
std::vector<uint8_t> roundTrip(const uint8_t* record, int f, size_t length, uint16_t extraBytes) {
  const PointAttributes attributes = lasAttributes(f, extraBytes);
  const AttributeLayout layout = attributeLayout(attributes);
  std::vector<uint8_t> tail(layout.bytes);
  packLasAttributes(record, f, layout, attributes, tail.data());
  const PointRecord p = toPointRecord(record, las::isExtended(f), las::kRgbOffset[size_t(f)]);
  std::vector<uint8_t> out = recordOf(p, f, length);
  unpackLasAttributes(tail.data(), layout, attributes, f, out.data());
  return out;
}

TEST(LasAttributes, LayoutIsCompactAndEmptyWithoutAttributes) {
  EXPECT_EQ(attributeLayout(PointAttributes{}).bytes, 0u);
  const AttributeLayout pf1 = attributeLayout(lasAttributes(1, 0));
  EXPECT_EQ(pf1.bytes, 8u + 2 + 1 + 1 + 1); // GPS time, scan angle, returns, flags, user data
  EXPECT_EQ(pf1.gpsTime, 0);
  EXPECT_EQ(pf1.nir, -1);
  const AttributeLayout pf8 = attributeLayout(lasAttributes(8, 3));
  EXPECT_EQ(pf8.bytes, 8u + 2 + 2 + 1 + 1 + 1 + 3);
  EXPECT_EQ(pf8.extraBytes, 15);
  EXPECT_EQ(attributeLayout(lasAttributes(2, 0)).gpsTime, -1);
}

TEST(LasAttributes, MergeRefusesWhatOneTailCannotHold) {
  bool ok = false;
  const PointAttributes m = mergeAttributes(lasAttributes(6, 0), lasAttributes(8, 0), ok);
  EXPECT_TRUE(ok);
  EXPECT_TRUE(m.nir && m.gpsTime && m.extendedScanAngle);
  mergeAttributes(lasAttributes(1, 0), lasAttributes(6, 0), ok);
  EXPECT_FALSE(ok); // scan angle in degrees and in 0.006 degree units
  mergeAttributes(lasAttributes(6, 4), lasAttributes(6, 2), ok);
  EXPECT_FALSE(ok);
  mergeAttributes(lasAttributes(6, 4), lasAttributes(6, 0), ok);
  EXPECT_TRUE(ok);
}

TEST(LasAttributes, RandomRecordsOfEveryFormatComeBackByteForByte) {
  std::mt19937 rng(7);
  for (int f = 0; f <= las::kMaxPointFormat; ++f)
    for (uint16_t extra : {uint16_t(0), uint16_t(5)}) {
      const size_t length = las::kRecordSize[size_t(f)] + extra;
      for (int k = 0; k < 200; ++k) {
        std::vector<uint8_t> record(length);
        for (uint8_t& b : record)
          b = static_cast<uint8_t>(rng());
        if (const int w = wavePacketOffset(f); w >= 0) std::memset(record.data() + w, 0, 29);
        ASSERT_EQ(roundTrip(record.data(), f, length, extra), record) << "format " << f << ", record " << k;
      }
    }
}

TEST(LasAttributes, Format1ThroughFormat6KeepsEveryValue) {
  std::mt19937 rng(11);
  const PointAttributes a1 = lasAttributes(1, 0), a6 = lasAttributes(6, 0);
  const AttributeLayout l1 = attributeLayout(a1), l6 = attributeLayout(a6);
  for (int k = 0; k < 500; ++k) {
    std::vector<uint8_t> record(las::kRecordSize[1]);
    for (uint8_t& b : record)
      b = static_cast<uint8_t>(rng());
    std::vector<uint8_t> tail1(l1.bytes), tail6(l6.bytes), back(l1.bytes);
    packLasAttributes(record.data(), 1, l1, a1, tail1.data());
    const PointRecord p = toPointRecord(record.data(), false, -1);
    std::vector<uint8_t> as6 = recordOf(p, 6, las::kRecordSize[6]);
    unpackLasAttributes(tail1.data(), l1, a1, 6, as6.data());
    // The format 6 record's values: GPS time equal, angle in 0.006 degree units within half a unit.
    EXPECT_EQ(std::memcmp(as6.data() + 22, record.data() + 20, 8), 0);
    EXPECT_NEAR(loadLE<int16_t>(as6.data() + 18) * 0.006, double(int8_t(record[16])), 0.003);
    EXPECT_EQ(as6[14] >> 4, (record[14] >> 3) & 7);
    EXPECT_EQ(as6[17], record[17]);
    packLasAttributes(as6.data(), 6, l6, a6, tail6.data());
    std::vector<uint8_t> as1 = recordOf(toPointRecord(as6.data(), true, -1), 1, las::kRecordSize[1]);
    unpackLasAttributes(tail6.data(), l6, a6, 1, as1.data());
    ASSERT_EQ(as1, record) << "record " << k;
  }
}

TEST(LasAttributes, RecordsOfRealFilesComeBackByteForByte) {
  for (const char* name :
       {"las/autzen_trim.las", "las/extrabytes.las", "las/test1_4.las", "las/autzen_trim_7.las",
        "las/las_with_several_extra_byte_bloc.las", "las/mvk-thin.las", "las/epsg_4326.las"}) {
    POINTRAST_REQUIRE_DATA(name);
    const InputFile file(test::dataDir() / name);
    const LasHeader h = readLasHeader(file);
    const uint16_t base = las::kRecordSize[size_t(h.pointFormat)];
    ASSERT_GE(h.recordLength, base) << name;
    const uint16_t extra = static_cast<uint16_t>(h.recordLength - base);
    const uint64_t n = std::min<uint64_t>(h.pointCount, 20'000);
    std::vector<uint8_t> bytes(n * h.recordLength);
    file.readAt(h.pointOffset, bytes.data(), bytes.size());
    for (uint64_t i = 0; i < n; ++i) {
      const uint8_t* record = bytes.data() + i * h.recordLength;
      ASSERT_EQ(roundTrip(record, h.pointFormat, h.recordLength, extra),
                std::vector<uint8_t>(record, record + h.recordLength))
          << name << ", record " << i;
    }
  }
}

// The payloads of every extra bytes VLR of a file, concatenated.
std::vector<uint8_t> extraBytesDescriptors(const InputFile& file, const LasHeader& h) {
  std::vector<uint8_t> out;
  for (const LasVlr& v : h.vlrs)
    if (v.userId == "LASF_Spec" && v.recordId == 4) {
      const size_t at = out.size();
      out.resize(at + v.length);
      file.readAt(v.dataOffset, out.data() + at, v.length);
    }
  return out;
}

std::vector<uint8_t> descriptor(uint8_t type, uint8_t options, const char* name) {
  std::vector<uint8_t> d(192, 0);
  d[2] = type;
  d[3] = options;
  std::memcpy(d.data() + 4, name, std::strlen(name));
  return d;
}

TEST(LasAttributes, ExtraBytesDescriptorsOfRealFiles) {
  {
    POINTRAST_REQUIRE_DATA("las/extrabytes.las");
    const InputFile file(test::dataDir() / "las/extrabytes.las");
    const LasHeader h = readLasHeader(file);
    const auto fields = parseExtraBytes(extraBytesDescriptors(file, h), 27, "extrabytes.las");
    // R15 Table 25: type 23 = three uint16, 0 with options 7 = 7 undocumented bytes, 12 = two int8,
    // 5 = uint32, 7 = uint64.
    ASSERT_EQ(fields.size(), 5u);
    const char* names[] = {"Colors", "Reserved", "Flags", "Intensity", "Time"};
    const char* types[] = {"uint16", "uint8", "int8", "uint32", "uint64"};
    const int elements[] = {3, 7, 2, 1, 1}, offsets[] = {0, 6, 13, 15, 19};
    for (size_t i = 0; i < fields.size(); ++i) {
      EXPECT_EQ(fields[i].name, names[i]);
      EXPECT_STREQ(fields[i].type, types[i]);
      EXPECT_EQ(fields[i].elements, elements[i]);
      EXPECT_EQ(fields[i].offset, offsets[i]);
    }
    EXPECT_EQ(fields[3].description, "Brightness");
  }
  {
    POINTRAST_REQUIRE_DATA("las/las_with_several_extra_byte_bloc.las");
    const InputFile file(test::dataDir() / "las/las_with_several_extra_byte_bloc.las");
    const LasHeader h = readLasHeader(file);
    const auto fields = parseExtraBytes(extraBytesDescriptors(file, h), 3, "several");
    ASSERT_EQ(fields.size(), 2u); // one descriptor in each of two VLRs
    EXPECT_EQ(fields[0].name, "Deviation");
    EXPECT_STREQ(fields[0].type, "uint16");
    EXPECT_EQ(fields[1].name, "confidence");
    EXPECT_EQ(fields[1].offset, 2);
  }
}

TEST(LasAttributes, ExtraBytesDescriptorsAreChecked) {
  std::vector<uint8_t> d = descriptor(10, 0x08, "height");
  storeLE<double>(d.data() + 112, 0.01);
  const auto fields = parseExtraBytes(d, 12, "x.las");
  ASSERT_EQ(fields.size(), 2u);
  EXPECT_STREQ(fields[0].type, "double");
  EXPECT_EQ(fields[0].scale[0], 0.01);
  EXPECT_EQ(fields[1].name, "extra bytes"); // 4 bytes no descriptor names
  EXPECT_EQ(fields[1].bytes, 4);
  EXPECT_EQ(fields[1].offset, 8);
  EXPECT_THROW(parseExtraBytes(d, 7, "x.las"), InputError);                        // longer than the records'
  EXPECT_THROW(parseExtraBytes(descriptor(31, 0, "bad"), 8, "x.las"), InputError); // unknown type
  EXPECT_THROW(parseExtraBytes(std::vector<uint8_t>(100), 8, "x.las"), InputError); // not whole descriptors
  EXPECT_TRUE(parseExtraBytes({}, 0, "x.las").empty());
}

} // namespace
} // namespace pointrast::io::detail

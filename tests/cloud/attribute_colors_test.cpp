// Coloring by attribute on the CPU side: names, palettes, explicit modes and their ranges, and the record
// path of the LOD sources giving what the PointCloud path gives.
#include "cloud/attribute_colors.h"

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/error.h"
#include "test_clouds.h"

namespace pointrast {
namespace {

using Source = DisplayColorMode::Source;

// A cloud of five points with every attribute set by hand; z = 10 * i metres.
PointCloud attributeCloud() {
  PointCloud cloud;
  cloud.scale = glm::dvec3(0.01);
  cloud.source = "hand.las";
  for (int i = 0; i < 5; ++i) {
    cloud.positions.insert(cloud.positions.end(), {i * 100, 0, i * 1000});
    cloud.colors.push_back(packRgba(10 * i, 20, 30));
    cloud.intensity.push_back(uint16_t(100 * i));
    cloud.classification.push_back(uint8_t(std::vector<int>{2, 6, 9, 5, 200}[size_t(i)]));
    cloud.returnNumber.push_back(uint8_t(i + 1));
    cloud.pointSourceId.push_back(uint16_t(7 + i));
  }
  computeBounds(cloud);
  return cloud;
}

std::vector<uint32_t> colorsOf(const PointCloud& cloud, const DisplayColorMode& mode) {
  std::vector<uint32_t> out(cloud.size());
  displayColors(out.data(), cloud, 0, cloud.size(), mode);
  return out;
}

TEST(AttributeColors, NamesRoundTripAndUnknownNamesListTheChoices) {
  for (Source s : {Source::Rgb, Source::Intensity, Source::Elevation, Source::Classification,
                   Source::ReturnNumber, Source::PointSource})
    EXPECT_EQ(parseColorSource(colorSourceName(s)), s);
  try {
    parseColorSource("height");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("classification"), std::string::npos) << e.what();
  }
}

TEST(AttributeColors, EachModeMapsTheHandBuiltCloud) {
  PointCloud cloud = attributeCloud();
  EXPECT_EQ(colorsOf(cloud, displayColorMode(cloud, Source::Rgb))[3], packRgba(30, 20, 30));

  ColorRange intensityRange{0, 400};
  std::vector<uint32_t> gray = colorsOf(cloud, displayColorMode(cloud, Source::Intensity, intensityRange));
  EXPECT_EQ(gray[0], packRgba(0, 0, 0));
  EXPECT_EQ(gray[2], packRgba(128, 128, 128)); // 0.5 * 255 = 127.5 rounds up
  EXPECT_EQ(gray[4], packRgba(255, 255, 255));

  ColorRange elevationRange{0, 40};
  std::vector<uint32_t> ramp = colorsOf(cloud, displayColorMode(cloud, Source::Elevation, elevationRange));
  for (int k = 0; k < 5; ++k)
    EXPECT_EQ(ramp[size_t(k)], elevationColor(k / 4.0));
  // Turbo: blue a quarter up, orange three quarters up.
  EXPECT_GT(ramp[1] >> 16 & 0xFF, 3 * (ramp[1] & 0xFF));
  EXPECT_GT(ramp[3] & 0xFF, 3 * (ramp[3] >> 16 & 0xFF));

  std::vector<uint32_t> classes = colorsOf(cloud, displayColorMode(cloud, Source::Classification));
  EXPECT_EQ(classes[0], packRgba(166, 110, 60)); // ground
  EXPECT_EQ(classes[1], packRgba(235, 140, 40)); // building
  EXPECT_EQ(classes[2], packRgba(40, 110, 230)); // water
  EXPECT_EQ(classes[3], packRgba(20, 110, 30));  // high vegetation
  EXPECT_EQ(classes[4] >> 24, 255u);             // a user class gets a color of its own

  std::vector<uint32_t> returns = colorsOf(cloud, displayColorMode(cloud, Source::ReturnNumber));
  EXPECT_EQ(returns[0], packRgba(230, 50, 40)); // first returns red
  EXPECT_EQ(returns[1], packRgba(40, 180, 60));
  EXPECT_EQ(std::set<uint32_t>(returns.begin(), returns.end()).size(), 5u);

  std::vector<uint32_t> sources = colorsOf(cloud, displayColorMode(cloud, Source::PointSource));
  EXPECT_EQ(std::set<uint32_t>(sources.begin(), sources.end()).size(), 5u);
  for (uint32_t c : sources)
    EXPECT_EQ(c >> 24, 255u);
}

TEST(AttributeColors, ConsecutiveSourceIdsGetDistantHues) {
  for (uint16_t id = 0; id < 200; ++id) {
    uint32_t a = pointSourceColor(id), b = pointSourceColor(uint16_t(id + 1));
    int d = 0;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::abs(int(a >> (8 * c) & 0xFF) - int(b >> (8 * c) & 0xFF)));
    EXPECT_GT(d, 60) << "ids " << id << " and " << id + 1;
  }
}

TEST(AttributeColors, UserClassesDifferFromEachOther) {
  std::set<uint32_t> seen;
  for (int c = 23; c < 256; ++c)
    seen.insert(classificationColor(uint8_t(c)));
  EXPECT_GT(seen.size(), 200u);
}

TEST(AttributeColors, RangesComeFromRobustPercentilesUnlessGiven) {
  PointCloud cloud = testing::randomCloud(100'000, 10'000); // z within +-10 m
  cloud.positions[2] = 1'000'000;                           // one bird at 1 km
  computeBounds(cloud);
  cloud.intensity.resize(cloud.size());
  for (uint64_t i = 0; i < cloud.size(); ++i)
    cloud.intensity[i] = uint16_t(i % 1000);
  cloud.intensity[5] = 60000; // one glint
  DisplayColorMode z = displayColorMode(cloud, Source::Elevation);
  EXPECT_LT(z.lo, -9.0);
  EXPECT_GT(z.hi, 9.0);
  EXPECT_LT(z.hi, 20.0);
  DisplayColorMode i = displayColorMode(cloud, Source::Intensity);
  EXPECT_NEAR(i.lo, 5.0, 16.0);
  EXPECT_NEAR(i.hi, 995.0, 16.0);
  DisplayColorMode given = displayColorMode(cloud, Source::Elevation, ColorRange{100, 200});
  EXPECT_EQ(given.lo, 100.0);
  EXPECT_EQ(given.hi, 200.0);
}

TEST(AttributeColors, MissingAttributeIsAnInputErrorNamingTheCloud) {
  PointCloud cloud = attributeCloud();
  cloud.classification.clear();
  cloud.pointSourceId.clear();
  for (Source s : {Source::Classification, Source::PointSource}) {
    try {
      displayColorMode(cloud, s);
      FAIL() << "no error for " << colorSourceName(s);
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("hand.las"), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(displayColorMode(cloud, Source::Elevation)); // every cloud has positions
}

TEST(AttributeColors, RecordsColorLikeTheCloudTheyBecome) {
  PointCloud cloud = attributeCloud();
  std::vector<PointRecord> records(cloud.size());
  for (uint64_t i = 0; i < cloud.size(); ++i) {
    PointRecord& r = records[i];
    r.x = cloud.positions[3 * i];
    r.y = cloud.positions[3 * i + 1];
    r.z = cloud.positions[3 * i + 2];
    for (int c = 0; c < 3; ++c)
      r.rgb[c] = uint16_t((cloud.colors[i] >> (8 * c) & 0xFF) << 8); // 16-bit colors
    r.intensity = cloud.intensity[i];
    r.classification = cloud.classification[i];
    r.returnNumber = cloud.returnNumber[i];
    r.pointSourceId = cloud.pointSourceId[i];
  }
  for (Source s : {Source::Rgb, Source::Intensity, Source::Elevation, Source::Classification,
                   Source::ReturnNumber, Source::PointSource}) {
    DisplayColorMode mode = displayColorMode(cloud, s);
    std::vector<uint32_t> fromRecords(records.size());
    recordColors(fromRecords.data(), records.data(), records.size(), mode, cloud.scale.z, cloud.offset.z, 8);
    EXPECT_EQ(fromRecords, colorsOf(cloud, mode)) << colorSourceName(s);
  }
}

} // namespace
} // namespace pointrast

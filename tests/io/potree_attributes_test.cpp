// The Potree 2.0 attributes of an attribute tail: named and typed as PotreeConverter's own metadata.json
// names the same LAS input's attributes, extra bytes under their descriptors' names.
#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "io/potree/potree_attributes.h"
#include "io/potree/potree_format.h"
#include "test_data.h"

namespace pointrast::io::potree {
namespace {

TEST(PotreeAttributes, NamedAndTypedAsPotreeConverterNamesThem) {
  // PotreeConverter's octree of autzen_trim.las (LAS 1.2, point format 3).
  POINTRAST_REQUIRE_DATA("potree/autzen_trim_default/metadata.json");
  std::ifstream in(test::dataDir() / "potree/autzen_trim_default/metadata.json");
  const nlohmann::json theirs = nlohmann::json::parse(in);
  const PointAttributes attributes = detail::lasAttributes(3, 0);
  const std::vector<TailAttribute> ours = tailAttributes(attributes, attributeLayout(attributes), {});
  RecordFields all;
  all.color = all.intensity = all.returnNumber = all.classification = all.pointSourceId = true;
  std::set<std::string> recordNames;
  for (const Attribute& a : writerLayout(all).attributes)
    recordNames.insert(a.name);
  size_t matched = 0;
  for (const auto& a : theirs.at("attributes")) {
    const std::string name = a.at("name");
    if (recordNames.count(name)) continue;
    bool found = false;
    for (const TailAttribute& t : ours)
      if (t.name == name) {
        found = true;
        EXPECT_EQ(t.type, a.at("type").get<std::string>()) << name;
        EXPECT_EQ(t.size, a.at("size").get<int>()) << name;
        EXPECT_EQ(t.numElements, a.at("numElements").get<int>()) << name;
        EXPECT_EQ(t.elementSize, a.at("elementSize").get<int>()) << name;
      }
    EXPECT_TRUE(found) << "PotreeConverter keeps \"" << name << "\"";
    matched += found;
  }
  EXPECT_EQ(matched, 4u); // number of returns, scan angle rank, user data, gps-time
}

TEST(PotreeAttributes, EveryTailByteBelongsToOneAttribute) {
  for (int f : {1, 6, 8}) {
    const PointAttributes attributes = detail::lasAttributes(f, 3);
    const AttributeLayout layout = attributeLayout(attributes);
    std::vector<detail::ExtraBytesField> extra(2);
    extra[0].name = "a";
    extra[0].bytes = extra[0].elementSize = 2;
    extra[0].type = "uint16";
    extra[1].name = "b";
    extra[1].offset = 2;
    extra[1].bytes = extra[1].elementSize = 1;
    std::vector<int> bits(layout.bytes * 8, 0);
    for (const TailAttribute& t : tailAttributes(attributes, layout, extra)) {
      if (t.bits > 0) {
        for (int b = 0; b < t.bits; ++b)
          ++bits[size_t(t.tailOffset * 8 + t.shift + b)];
      } else {
        // The rank's one byte stands for the tail's int16 (a value of -128..127).
        const int bytes = t.name == "scan angle rank" ? 2 : t.size;
        for (int b = 0; b < 8 * bytes; ++b)
          ++bits[size_t(t.tailOffset * 8 + b)];
      }
    }
    for (size_t b = 0; b < bits.size(); ++b)
      EXPECT_EQ(bits[b], 1) << "format " << f << ", tail bit " << b;
  }
}

} // namespace
} // namespace pointrast::io::potree

// The format table: detection by content before extension, the generated lists and messages, and the
// capabilities each row declares (a row that says it reads a cloud reads one of the shared data files).
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "cloud/octree.h"
#include "io/format_table.h"
#include "io_test_util.h"

using namespace pointrast;
using namespace pointrast::io;
using iotest::formatOf;

TEST(FormatTable, ContentDecidesBeforeTheExtension) {
  iotest::TempDir dir;
  iotest::writeText(dir / "looks.xyz", "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n");
  EXPECT_EQ(formatOf(dir / "looks.xyz"), "PLY");
  iotest::writeText(dir / "plain.csv", "1,2,3\n");
  EXPECT_EQ(formatOf(dir / "plain.csv"), "XYZ");
  EXPECT_EQ(formatOf(dir.path()), ""); // a folder that is no octree
}

TEST(FormatTable, NamesAreUniqueAndEveryPointRowCanBeReadOrSaysWhy) {
  std::set<std::string> names;
  for (const FormatInfo& f : formatTable()) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_TRUE(f.detect || *f.extensions) << f.name << " cannot be recognised";
    EXPECT_EQ(f.read != nullptr, f.probe != nullptr) << f.name << ": `info` and `render` read the same files";
    EXPECT_TRUE(f.read || f.openNodes || f.refuse) << f.name << " is recognised but never read nor refused";
  }
}

TEST(FormatTable, UnknownContentNamesEveryFormat) {
  iotest::TempDir dir;
  iotest::writeText(dir / "a.dat", "1 2 3\n");
  try {
    readCloud(dir / "a.dat", iotest::quiet());
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string text = e.what();
    for (const FormatInfo& f : formatTable())
      EXPECT_NE(text.find(f.name), std::string::npos) << text;
    EXPECT_NE(text.find(".pts"), std::string::npos) << text; // extension-only rows list their extensions
  }
}

TEST(FormatTable, ListsComeFromTheRows) {
  const std::string clouds = formatList(FormatUse::Cloud), particles = formatList(FormatUse::Particles);
  for (const FormatInfo& f : formatTable()) {
    EXPECT_EQ(clouds.find(f.name) != std::string::npos, f.read != nullptr) << f.name << " in " << clouds;
    EXPECT_EQ(particles.find(f.name) != std::string::npos, f.content == FormatContent::Particles) << f.name;
  }
  EXPECT_NE(clouds.find("XYZ (.xyz, .txt, .csv, .pts)"), std::string::npos) << clouds;
  EXPECT_NE(clouds.find(" and "), std::string::npos) << clouds;
}

TEST(FormatTable, AnInputThatIsNoOctreeIsRefusedAsLodSource) {
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  EXPECT_THROW(openNodeSource(iotest::data("las/autzen_trim.las")), InputError);
}

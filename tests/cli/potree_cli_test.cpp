// Potree 2.0 octree folders through the CLI: info describes them, convert exports them exactly, render
// draws every point (the same image as the exported LAS), damaged ones fail with one line and exit 1.
#include <filesystem>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "io/potree_test_util.h"

namespace {

namespace fs = std::filesystem;
using pointrast::test::CliResult;
using pointrast::test::runPointrast;
using namespace pointrast;

fs::path octreeDir(const std::string& name) {
  return pointrast::test::cliTempDir() / name;
}

// A written octree (replacing an older one of that name) and the tree it holds.
potreetest::Tree writeOctree(const std::string& name, io::PotreeEncoding encoding,
                             bool fromPotreeConverter = false) {
  const potreetest::Tree tree =
      potreetest::makeTree({.points = 5000, .depth = 4, .color16 = true, .seed = 11});
  fs::remove_all(octreeDir(name));
  io::PotreeWriteOptions o;
  o.encoding = encoding;
  o.hierarchyStepSize = 2;
  potreetest::writeTree(tree, octreeDir(name), o);
  if (fromPotreeConverter) {
    std::ifstream in(octreeDir(name) / "metadata.json");
    nlohmann::json meta = nlohmann::json::parse(in);
    meta.erase("generator");
    iotest::writeText(octreeDir(name) / "metadata.json", meta.dump(1));
  }
  return tree;
}

void expectOneErrorLine(const CliResult& r, const std::string& args) {
  EXPECT_FALSE(r.signaled) << args;
  EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
  int lines = 0;
  for (size_t at = r.err.find("pointrast:"); at != std::string::npos; at = r.err.find("pointrast:", at + 1))
    ++lines;
  EXPECT_EQ(lines, 1) << args << "\n" << r.err;
}

TEST(PotreeCli, InfoDescribesTheOctree) {
  const potreetest::Tree tree = writeOctree("info", io::PotreeEncoding::Brotli);
  const CliResult r = runPointrast("info " + octreeDir("info").string());
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const std::string& line : std::vector<std::string>{
           "format:  Potree 2.0 octree, BROTLI encoding, written by pointrast", "points:  5000",
           "bounds:  ", "color:   RGB, 16-bit", "scale:   0.001, 0.001, 0.001",
           "nodes:   " + std::to_string(tree.nodes.size()), "depth:   4 levels below the root",
           "spacing: ", "attributes: position (int32 x3), intensity (uint16), ", "encoding: BROTLI",
           "hierarchy: chunks of 2 levels", "coordinates: exact"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\nin\n" << r.out;

  const CliResult j = runPointrast("info " + (octreeDir("info") / "metadata.json").string() + " --json");
  ASSERT_EQ(j.exitCode, 0) << j.err;
  const nlohmann::json info = nlohmann::json::parse(j.out);
  EXPECT_EQ(info["format"], "Potree 2.0");
  EXPECT_EQ(info["points"], 5000);
  EXPECT_EQ(info["color_bits"], 16);
  EXPECT_EQ(info["extra"]["nodes"], std::to_string(tree.nodes.size()));

  writeOctree("pc", io::PotreeEncoding::Default, true);
  const CliResult pc = runPointrast("info " + octreeDir("pc").string());
  ASSERT_EQ(pc.exitCode, 0) << pc.err;
  EXPECT_NE(pc.out.find("written by PotreeConverter"), std::string::npos) << pc.out;
  EXPECT_NE(pc.out.find("may sit one quantum low"), std::string::npos) << pc.out;
}

TEST(PotreeCli, ConvertExportsEveryPointExactly) {
  const potreetest::Tree tree = writeOctree("convert", io::PotreeEncoding::Brotli);
  const fs::path las = pointrast::test::cliTempDir() / "octree.las";
  fs::remove(las);
  const CliResult r = runPointrast("convert " + octreeDir("convert").string() + " " + las.string() + " -q");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // Classes up to 39 need LAS 1.4's point format 7 to stay exact.
  const io::FileInfo info = io::probeFile(las);
  EXPECT_NE(info.formatDetail.find("point format 7"), std::string::npos) << info.formatDetail;
  EXPECT_EQ(info.colorBits, 16);
  const PointCloud cloud = io::readCloud(las, iotest::quiet());
  EXPECT_EQ(cloud.scale, tree.meta.scale);
  EXPECT_EQ(cloud.offset, tree.meta.offset);
  std::multiset<std::tuple<int32_t, int32_t, int32_t, uint16_t, uint8_t, uint8_t>> expected, got;
  for (const auto& [key, records] : tree.nodes)
    for (const PointRecord& p : records)
      expected.insert({p.x, p.y, p.z, p.intensity, p.classification, p.returnNumber});
  for (uint64_t i = 0; i < cloud.size(); ++i)
    got.insert({cloud.positions[3 * i], cloud.positions[3 * i + 1], cloud.positions[3 * i + 2],
                cloud.intensity[i], cloud.classification[i], cloud.returnNumber[i]});
  EXPECT_EQ(got, expected);
}

TEST(PotreeCli, RenderDrawsWhatTheExportedLasDraws) {
  writeOctree("render", io::PotreeEncoding::Default);
  const fs::path las = pointrast::test::cliTempDir() / "render.las";
  const fs::path a = pointrast::test::cliTempDir() / "octree.png",
                 b = pointrast::test::cliTempDir() / "las.png";
  fs::remove(las);
  ASSERT_EQ(runPointrast("convert " + octreeDir("render").string() + " " + las.string() + " -q").exitCode, 0);
  const std::string view = " --width 320 --height 240 --frames 1 --json";
  const CliResult ra = runPointrast("render " + octreeDir("render").string() + " -o " + a.string() + view);
  const CliResult rb = runPointrast("render " + las.string() + " -o " + b.string() + view);
  ASSERT_EQ(ra.exitCode, 0) << ra.err;
  ASSERT_EQ(rb.exitCode, 0) << rb.err;
  const nlohmann::json ja = nlohmann::json::parse(ra.out), jb = nlohmann::json::parse(rb.out);
  EXPECT_EQ(ja["points"], 5000);
  EXPECT_EQ(ja["image_hash"], jb["image_hash"]);
}

TEST(PotreeCli, DamagedOctreesFailWithOneLine) {
  writeOctree("bad", io::PotreeEncoding::Brotli);
  const fs::path png = pointrast::test::cliTempDir() / "bad.png",
                 las = pointrast::test::cliTempDir() / "bad.las";
  const fs::path dir = octreeDir("bad");
  auto check = [&](const std::string& what) {
    for (const std::string& args : {"info " + dir.string(), "render " + dir.string() + " -o " + png.string(),
                                    "convert " + dir.string() + " " + las.string()}) {
      fs::remove(png);
      fs::remove(las);
      const CliResult r = runPointrast(args);
      expectOneErrorLine(r, what + ": " + args);
      EXPECT_FALSE(fs::exists(png)) << args;
      EXPECT_FALSE(fs::exists(las)) << args;
      for (const auto& entry : fs::directory_iterator(las.parent_path()))
        EXPECT_NE(entry.path().filename().string().rfind("bad.las.partial", 0), 0u) << entry.path();
    }
  };
  const std::vector<uint8_t> octree = iotest::readBytes(dir / "octree.bin");
  iotest::writeBytes(dir / "octree.bin", octree.data(), octree.size() - 1);
  check("octree.bin one byte short");
  iotest::writeBytes(dir / "octree.bin", octree);
  const std::vector<uint8_t> hierarchy = iotest::readBytes(dir / "hierarchy.bin");
  iotest::writeBytes(dir / "hierarchy.bin", hierarchy.data(), hierarchy.size() / 2);
  check("hierarchy.bin cut in half");
  iotest::writeBytes(dir / "hierarchy.bin", hierarchy);
  // A node that claims points but holds no bytes, in a folder from another writer (no "generator"): read
  // as empty, its points would vanish from a conversion that exits 0.
  const std::vector<uint8_t> metadata = iotest::readBytes(dir / "metadata.json");
  nlohmann::json j = nlohmann::json::parse(metadata.begin(), metadata.end());
  j.erase("generator");
  iotest::writeText(dir / "metadata.json", j.dump());
  potreetest::patchRecord(dir, potreetest::NodeKey{}, false, [](io::potree::Record& r) { r.byteSize = 0; });
  check("a node with points and no bytes");
  iotest::writeBytes(dir / "hierarchy.bin", hierarchy);
  iotest::writeText(dir / "metadata.json", "{\"version\": \"2.0\"}");
  check("metadata.json without fields");
}

} // namespace

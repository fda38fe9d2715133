// Distributed rendering as a user starts it: `mpirun -np N pointrast render ...` on lavapipe, compared
// with the same render on one rank. Closest-point frames must composite to the one-rank frame exactly;
// where a batch or LOD method's words differ, both words must hold the same depth (a tie the one-rank
// frame breaks by point index, the composite by color).
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include "cli/cli_harness.h"
#include "mpi/mpi_harness.h"
#include "mpi/mpi_job.h"
#include "test_data.h"

namespace fs = std::filesystem;
using pointrast::test::cliTempDir;
using pointrast::test::pointrastBinary;
using pointrast::test::runPointrast;
using pointrast::test::slurp;

namespace {

using namespace pointrast::test::mpi;

// One render of `args` on `ranks` ranks (extra mpirun options first); the composited words and the JSON.
struct Frame {
  std::vector<uint64_t> words;
  nlohmann::json json;
};
Frame renderOn(uint32_t ranks, const std::string& args, const std::string& mpirunOptions = "",
               const std::string& env = "") {
  const fs::path words = cliTempDir() / ("words_" + std::to_string(ranks) + ".bin");
  fs::remove(words);
  const MpiRun r = runMpi(mpirunOptions + " -np " + std::to_string(ranks) + " " + pointrastBinary() +
                              " render " + args + " --json -q",
                          "POINTRAST_MPI_WORDS=" + words.string() + " " + env);
  EXPECT_EQ(r.exitCode, 0) << args << "\n" << r.err;
  Frame f;
  if (r.exitCode != 0) return f;
  f.words = readWords(words);
  f.json = nlohmann::json::parse(r.out);
  return f;
}

struct Difference {
  uint64_t pixels = 0, covered = 0, differ = 0, ties = 0;
};
// Pixels whose words differ, and how many of them are ties: both hold a point at the same depth.
Difference compare(const std::vector<uint64_t>& a, const std::vector<uint64_t>& b) {
  Difference d;
  d.pixels = a.size();
  for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (a[i] != kEmpty) ++d.covered;
    if (a[i] == b[i]) continue;
    ++d.differ;
    if (a[i] != kEmpty && b[i] != kEmpty && a[i] >> 32 == b[i] >> 32) ++d.ties;
  }
  return d;
}

// An explicit camera: the overview under mpirun is framed from rank 0's share (docs/mpi.md).
const std::string kImage = " --width 240 --height 160 --frames 1";
const std::string kTerrainView = " --eye 500022.37,3999984.26,217.29 --target 500022.37,4000018.99,192.97";

// A generated terrain of 40,000 points: four batches of 10,240 points or fewer, so three ranks get
// unequal shares.
std::string terrain(const std::string& out) {
  return "terrain --points 40000 -o " + (cliTempDir() / out).string() + kImage + kTerrainView;
}

TEST(MpiRender, AtomicMinComposesTheOneRankFrameExactly) {
  REQUIRE_MPI();
  const Frame one = renderOn(1, terrain("one.png"));
  const Frame two = renderOn(2, terrain("two.png"));
  const Frame three = renderOn(3, terrain("three.png"));
  ASSERT_FALSE(one.words.empty());
  ASSERT_EQ(one.words.size(), 240u * 160u);
  const Difference d2 = compare(one.words, two.words), d3 = compare(one.words, three.words);
  EXPECT_GT(d2.covered, d2.pixels / 4) << "the frame must show the scene";
  // MIN over depth << 32 | color words is the same MIN whichever rank a point was drawn by: no exceptions.
  EXPECT_EQ(d2.differ, 0u);
  EXPECT_EQ(d3.differ, 0u);
  EXPECT_EQ(two.json["image_hash"], one.json["image_hash"]);
  EXPECT_EQ(three.json["image_hash"], one.json["image_hash"]);
  EXPECT_EQ(three.json["points"], 40000);
  EXPECT_EQ(three.json["mpi"]["ranks"], 3);
  EXPECT_EQ(three.json["mpi"]["rank_render_ms"].size(), 3u);
  EXPECT_EQ(three.json["mpi"]["bytes_moved"], 2u * 240 * 160 * 8);
  EXPECT_GE(three.json["mpi"]["composite_ms"].get<double>(), 0.0);
  // A frame's stages one after another; every rank says which device it took.
  const nlohmann::json& stages = three.json["mpi"];
  EXPECT_NEAR(stages["frame_ms"].get<double>(),
              stages["render_ms"].get<double>() + stages["readback_ms"].get<double>() +
                  stages["composite_ms"].get<double>() + stages["resolve_ms"].get<double>(),
              1e-6);
  EXPECT_GT(stages["resolve_first_ms"].get<double>(), 0.0);
  for (const auto& device : stages["devices"])
    EXPECT_NE(device.get<std::string>().find(", device "), std::string::npos) << device;
  // And one rank under mpirun is today's render.
  const pointrast::test::CliResult plain = runPointrast("render " + terrain("plain.png") + " --json -q");
  ASSERT_EQ(plain.exitCode, 0) << plain.err;
  EXPECT_EQ(nlohmann::json::parse(plain.out)["image_hash"], one.json["image_hash"]);
}

TEST(MpiRender, BatchMethodDiffersFromOneRankOnlyAtDepthTies) {
  REQUIRE_MPI();
  const std::string args = terrain("batch.png") + " --method batch-prefetch --edl --point-size 2";
  const Frame one = renderOn(1, args);
  const Frame three = renderOn(3, args);
  ASSERT_FALSE(one.words.empty());
  ASSERT_FALSE(three.words.empty());
  const Difference d = compare(one.words, three.words);
  EXPECT_GT(d.covered, d.pixels / 4);
  EXPECT_EQ(d.differ, d.ties) << d.differ - d.ties << " pixels differ in depth";
  RecordProperty("depth_ties", std::to_string(d.ties));
  std::printf("batch-prefetch on 3 ranks: %llu of %llu covered pixels differ, all at depth ties\n",
              (unsigned long long)d.differ, (unsigned long long)d.covered);
  if (d.ties == 0) {
    EXPECT_EQ(three.json["image_hash"], one.json["image_hash"]);
  }
  // The resolve stage ran once, on the composite.
  EXPECT_TRUE(three.json.contains("post"));
}

// One render of `args` on `ranks` ranks for a method without composited words (HQS): its JSON and PNG.
struct Image {
  nlohmann::json json;
  std::string png;
};
Image imageOn(uint32_t ranks, const std::string& args, const fs::path& png) {
  fs::remove(png);
  const MpiRun r = runMpi("-np " + std::to_string(ranks) + " " + pointrastBinary() + " render " + args +
                          " -o " + png.string() + " --json -q");
  EXPECT_EQ(r.exitCode, 0) << args << "\n" << r.err;
  Image image;
  if (r.exitCode != 0) return image;
  image.json = nlohmann::json::parse(r.out);
  image.png = slurp(png);
  return image;
}

// HQS: the closest depth of all ranks to every rank, each rank's blend sums added on rank 0, resolved once:
// integer sums, so the frame is the one-rank frame bit for bit.
TEST(MpiRender, HqsComposesTheOneRankFrameExactly) {
  REQUIRE_MPI();
  const std::string scene = "terrain --points 40000" + kImage + kTerrainView;
  for (const std::string method : {"hqs", "hqs1r"}) {
    const std::string args = scene + " --method " + method;
    const Image one = imageOn(1, args, cliTempDir() / "hqs1.png");
    const Image two = imageOn(2, args, cliTempDir() / "hqs2.png");
    const Image three = imageOn(3, args, cliTempDir() / "hqs3.png");
    ASSERT_FALSE(one.png.empty());
    EXPECT_EQ(two.json["image_hash"], one.json["image_hash"]) << method;
    EXPECT_EQ(three.json["image_hash"], one.json["image_hash"]) << method;
    EXPECT_TRUE(two.png == one.png) << method;
    EXPECT_TRUE(three.png == one.png) << method;
    EXPECT_EQ(three.json["points"], 40000);
    EXPECT_EQ(three.json["mpi"]["ranks"], 3);
    EXPECT_EQ(three.json["mpi"]["bytes_moved"], 2u * 240 * 160 * 32);
  }
  // The frame blends: it is not the closest-point frame of the same view.
  const Image closest = imageOn(1, scene, cliTempDir() / "closest.png");
  const Image blended = imageOn(1, scene + " --method hqs", cliTempDir() / "hqs1.png");
  EXPECT_NE(closest.json["image_hash"], blended.json["image_hash"]);
  // One rank under mpirun is the plain render, and the resolve stage runs once on the composite.
  const fs::path plainPng = cliTempDir() / "hqs_plain.png";
  const pointrast::test::CliResult plain =
      runPointrast("render " + scene + " --method hqs --edl -o " + plainPng.string() + " --json -q");
  ASSERT_EQ(plain.exitCode, 0) << plain.err;
  const Image edl = imageOn(3, scene + " --method hqs --edl", cliTempDir() / "hqs_edl.png");
  EXPECT_EQ(edl.json["image_hash"], nlohmann::json::parse(plain.out)["image_hash"]);
  EXPECT_TRUE(edl.json.contains("post"));
}

// batch-hqs in the same two steps, drawn without its dense-batch path (which blends a dense batch against
// the rank's own depths): the frame of one process drawing it whole, dense path included, bit for bit. From
// far away at 60x40 one of the four Morton-ordered batches is dense.
TEST(MpiRender, BatchHqsComposesTheOneProcessFrameExactly) {
  REQUIRE_MPI();
  const std::string scene = "terrain --points 40000 --order morton --width 60 --height 40 --frames 1 --fov 3 "
                            "--eye 500022.35,3999419.41,620.0 --target 500022.35,4000022.37,197.80";
  const std::string args = scene + " --method batch-hqs";
  auto plain = [&](const std::string& extra) {
    const pointrast::test::CliResult r = runPointrast("render " + args + extra + " --json -q -o " +
                                                      (cliTempDir() / "bhqs_plain.png").string());
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return r.exitCode == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
  };
  const nlohmann::json whole = plain("");
  ASSERT_TRUE(whole.contains("batch_stats"));
  EXPECT_GT(whole["batch_stats"]["batches_dense"].get<int>(), 0)
      << "the dense path must be part of the frame";
  const Image two = imageOn(2, args, cliTempDir() / "bhqs2.png");
  ASSERT_FALSE(two.png.empty());
  EXPECT_EQ(two.json["image_hash"], whole["image_hash"]);
  EXPECT_EQ(two.json["points"], 40000);
  EXPECT_EQ(two.json["mpi"]["bytes_moved"], 60u * 40u * 32);
  // The resolve stage once on the composite of three ranks, as on one process.
  const Image three = imageOn(3, args + " --point-size 2", cliTempDir() / "bhqs3.png");
  EXPECT_EQ(three.json["image_hash"], plain(" --point-size 2")["image_hash"]);
  // The frame blends: it is not the closest-point frame of the batches.
  const pointrast::test::CliResult closest = runPointrast(
      "render " + scene + " --method batch --json -q -o " + (cliTempDir() / "bclosest.png").string());
  ASSERT_EQ(closest.exitCode, 0) << closest.err;
  EXPECT_NE(nlohmann::json::parse(closest.out)["image_hash"], whole["image_hash"]);
}

// lod-hqs in the same two steps, each rank blending its share of the octree's nodes (in several passes
// where its node cache is small): the frame of one process drawing the whole selection, bit for bit.
TEST(MpiRender, LodHqsComposesTheOneProcessFrameExactly) {
  REQUIRE_MPI();
  const fs::path las = cliTempDir() / "lodhqs_terrain.las", octree = cliTempDir() / "lodhqs_terrain";
  fs::remove_all(octree);
  ASSERT_EQ(runPointrast("generate terrain --points 60000 -o " + las.string() + " -q").exitCode, 0);
  const pointrast::test::CliResult built =
      runPointrast("lod " + las.string() + " -o " + octree.string() + " -q");
  ASSERT_EQ(built.exitCode, 0) << built.err;
  const std::string args = octree.string() + " --method lod-hqs --min-node-px 0" + kImage;
  const pointrast::test::CliResult plain =
      runPointrast("render " + args + " --json -q -o " + (cliTempDir() / "lodhqs_plain.png").string());
  ASSERT_EQ(plain.exitCode, 0) << plain.err;
  const nlohmann::json whole = nlohmann::json::parse(plain.out);
  const Image two = imageOn(2, args + " --gpu-memory 384k", cliTempDir() / "lodhqs2.png");
  ASSERT_FALSE(two.png.empty());
  EXPECT_EQ(two.json["image_hash"], whole["image_hash"]);
  EXPECT_EQ(two.json["points"], 60000);
  EXPECT_GT(two.json["lod_stats"]["passes"].get<int>(), 1);
  // The frame blends: it is not lod's closest-point frame.
  const pointrast::test::CliResult closest =
      runPointrast("render " + octree.string() + " --method lod --min-node-px 0" + kImage + " --json -q -o " +
                   (cliTempDir() / "lod_closest.png").string());
  ASSERT_EQ(closest.exitCode, 0) << closest.err;
  EXPECT_NE(nlohmann::json::parse(closest.out)["image_hash"], whole["image_hash"]);
}

TEST(MpiRender, AMethodWithoutDepthsIsRefusedWithOneLine) {
  REQUIRE_MPI();
  const MpiRun r =
      runMpi("-np 2 " + pointrastBinary() + " render terrain --points 20000 --method hw-points -o " +
                 (cliTempDir() / "refused.png").string() + kImage + " -q",
             "", 60);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("pointrast: hw-points keeps no depth per pixel"), std::string::npos) << r.err;
}

// The camera over autzen_trim that the file tests use.
const std::string kAutzenView = kImage + " --eye 636590,848500,1400 --target 636590,849216,463";

// A file of the shared data drawn on 1 and 3 ranks: the composite is the one-rank frame, and each rank
// drew its share of the 110,000 points (whole batches, as the whole file would be cut). The 3-rank frame.
Frame sharesComposeTheOneRankFrame(const std::string& file, const std::string& png) {
  const std::string args =
      (pointrast::test::dataDir() / file).string() + " -o " + (cliTempDir() / png).string() + kAutzenView;
  const Frame one = renderOn(1, args);
  const Frame three = renderOn(3, args);
  EXPECT_FALSE(one.words.empty());
  EXPECT_FALSE(three.words.empty());
  if (one.words.empty() || three.words.empty()) return three;
  const Difference d = compare(one.words, three.words);
  EXPECT_GT(d.covered, d.pixels / 10) << "the frame must show the file";
  EXPECT_EQ(d.differ, 0u);
  EXPECT_EQ(three.json["image_hash"], one.json["image_hash"]);
  const nlohmann::json& points = three.json["mpi"]["rank_points"];
  EXPECT_EQ(points.size(), 3u);
  for (uint32_t r = 0; r < 3 && r < points.size(); ++r)
    EXPECT_EQ(points[r].get<double>(), double(pointrast::mpi::rangeOf(110000, 10240, r, 3).count)) << r;
  return three;
}

// The frame of autzen_trim's LAS file drawn by one process without mpirun.
nlohmann::json oneProcessLas(const std::string& png) {
  const pointrast::test::CliResult plain =
      runPointrast("render " + (pointrast::test::dataDir() / "las/autzen_trim.las").string() + " -o " +
                   (cliTempDir() / png).string() + kAutzenView + " --json -q");
  EXPECT_EQ(plain.exitCode, 0) << plain.err;
  return plain.exitCode == 0 ? nlohmann::json::parse(plain.out) : nlohmann::json();
}

// A LAS file: each rank reads only its records.
TEST(MpiRender, LasSharesAreReadPerRankAndComposeTheOneRankFrame) {
  REQUIRE_MPI();
  POINTRAST_REQUIRE_DATA("las/autzen_trim.las");
  const Frame three = sharesComposeTheOneRankFrame("las/autzen_trim.las", "autzen.png");
  ASSERT_FALSE(three.words.empty());
  EXPECT_EQ(three.json["points"], 110000);
  EXPECT_LT(three.json["mpi"]["rank_points"][0].get<double>(), 110000.0);
  // And the whole file read by one process gives the same frame.
  EXPECT_EQ(oneProcessLas("autzen-plain.png")["image_hash"], three.json["image_hash"]);
}

// A LAZ file: each rank decodes only the chunks that hold its records (the file's chunks of 50,000 points
// cut across the ranks' batches), and the composite is the frame of the LAS twin drawn by one process.
TEST(MpiRender, LazSharesAreDecodedPerRankAndComposeTheOneRankFrame) {
  REQUIRE_MPI();
  POINTRAST_REQUIRE_DATA("laz/autzen_trim.laz");
  const Frame three = sharesComposeTheOneRankFrame("laz/autzen_trim.laz", "autzen-laz.png");
  ASSERT_FALSE(three.words.empty());
  EXPECT_EQ(oneProcessLas("autzen-twin.png")["image_hash"], three.json["image_hash"]);
}

// Standing in for several hosts: the tcp transport, and the composite by MPI_Reduce (ranks on several
// hosts share no memory); on one host the composite runs in shared memory, with the same frame.
TEST(MpiRender, TcpTransportGivesTheSameFrame) {
  REQUIRE_MPI();
  const Frame one = renderOn(1, terrain("tcp1.png"));
  const Frame two = renderOn(2, terrain("tcp2.png"), "--mca btl tcp,self", "POINTRAST_MPI_COMPOSITE=reduce");
  ASSERT_FALSE(two.words.empty());
  EXPECT_EQ(compare(one.words, two.words).differ, 0u);
  EXPECT_EQ(two.json["image_hash"], one.json["image_hash"]);
  EXPECT_EQ(two.json["mpi"]["composite_path"], "MPI_Reduce");
  const Frame shared = renderOn(2, terrain("tcp3.png"));
  EXPECT_EQ(shared.json["mpi"]["composite_path"], "shared memory");
  EXPECT_EQ(shared.json["image_hash"], one.json["image_hash"]);
  EXPECT_EQ(compare(one.words, shared.words).differ, 0u);
}

TEST(MpiRender, LodSharesWithASmallNodeCacheGiveTheOneRankFrame) {
  REQUIRE_MPI();
  const fs::path las = cliTempDir() / "lod_terrain.las", octree = cliTempDir() / "lod_terrain";
  fs::remove_all(octree);
  ASSERT_EQ(runPointrast("generate terrain --points 60000 -o " + las.string() + " -q").exitCode, 0);
  const pointrast::test::CliResult built =
      runPointrast("lod " + las.string() + " -o " + octree.string() + " -q");
  ASSERT_EQ(built.exitCode, 0) << built.err;
  const std::string args =
      octree.string() + " --method lod --min-node-px 0 -o " + (cliTempDir() / "lod.png").string() + kImage;
  const Frame one = renderOn(1, args);
  // Each rank's node cache holds six pages: its share is drawn in several passes.
  const Frame two = renderOn(2, args + " --gpu-memory 384k");
  ASSERT_FALSE(one.words.empty());
  ASSERT_FALSE(two.words.empty());
  const Difference d = compare(one.words, two.words);
  EXPECT_GT(d.covered, d.pixels / 4);
  EXPECT_EQ(d.differ, d.ties) << d.differ - d.ties << " pixels differ in depth";
  EXPECT_EQ(two.json["points"], 60000);
  EXPECT_GT(two.json["lod_stats"]["passes"].get<int>(), 1);
}

TEST(MpiRender, ARankWithADamagedFileEndsTheJobWithOneLine) {
  REQUIRE_MPI();
  const fs::path good = cliTempDir() / "good.las", bad = cliTempDir() / "damaged.las";
  const fs::path png = cliTempDir() / "damaged.png";
  ASSERT_EQ(runPointrast("generate terrain --points 20000 -o " + good.string() + " -q").exitCode, 0);
  fs::copy_file(good, bad, fs::copy_options::overwrite_existing);
  fs::resize_file(bad, fs::file_size(good) / 2); // the header promises twice the records present
  fs::remove(png);
  const std::string tail = " -o " + png.string() + kImage + " -q";
  const MpiRun r = runMpi("-np 1 " + pointrastBinary() + " render " + good.string() + tail + " : -np 1 " +
                              pointrastBinary() + " render " + bad.string() + tail,
                          "", 60);
  EXPECT_FALSE(r.signaled) << r.err;
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_LT(r.seconds, 60);
  int lines = 0;
  for (size_t at = r.err.find("pointrast:"); at != std::string::npos; at = r.err.find("pointrast:", at + 1))
    ++lines;
  EXPECT_EQ(lines, 1) << r.err;
  EXPECT_NE(r.err.find("pointrast: rank 1: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("damaged.las: header claims"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(png));
}

TEST(MpiRender, OtherCommandsRefuseSeveralRanks) {
  REQUIRE_MPI();
  const MpiRun r = runMpi("-np 2 " + pointrastBinary() + " info terrain", "", 60);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("pointrast: `pointrast info` runs as one process"), std::string::npos) << r.err;
}

// Annotations are drawn over one process's frame; under mpirun they are refused, not silently dropped.
TEST(MpiRender, AnnotationsAreRefusedUnderMpirun) {
  REQUIRE_MPI();
  const fs::path json = cliTempDir() / "label.json", png = cliTempDir() / "annotated.png";
  {
    std::ofstream out(json);
    out << R"({"version": 1, "annotations": [{"type": "label", "text": "x", "points": [[0, 0, 0]]}]})";
  }
  fs::remove(png);
  const MpiRun r = runMpi("-np 2 " + pointrastBinary() + " render terrain --points 20000 --annotations " +
                              json.string() + " -o " + png.string() + kImage + " -q",
                          "", 60);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("pointrast: --annotations draws over the frame of one process"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(png));
}

} // namespace

// render with the Filters group and --pick, as a user runs it:
// - --classes gives the image of rendering the file of the kept points (same image hash);
// - --clip-box culls whole batches and says so in --json;
// - --pick X,Y --json reports the closest point at that pixel with its attributes (checked against a
//   projection computed here), the point behind it once the first is filtered out, "none" on background;
// - bad --pick and filters of attributes the input lacks fail with one line.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "cli_harness.h"
#include "io/writer.h"

namespace pointrast::test {

namespace {

constexpr uint32_t kW = 160, kH = 120;
const glm::dvec3 kEye(5, 5, 30), kTarget(5, 5, 0), kUp(0, 1, 0);
const std::string kCamera =
    "--eye 5,5,30 --target 5,5,0 --up 0,1,0 --fov 60 --near 0.5 --width 160 --height 120";

// The ray through the center of pixel (x, y) of the camera above (the image contract of docs/design.md).
glm::dvec3 pixelRay(uint32_t x, uint32_t y) {
  const double t = std::tan(glm::radians(60.0) / 2), aspect = double(kW) / kH;
  const double nx = (x + 0.5) / kW * 2 - 1, ny = 1 - (y + 0.5) / kH * 2;
  // Looking down -z with y up: view x = world x, view y = world y.
  return glm::normalize(glm::dvec3(nx * t * aspect, ny * t, -1));
}

struct TestCloud {
  PointCloud cloud;
  size_t front = 0, behind = 0; // two points on the ray of the picked pixel
};

void addPoint(PointCloud& c, glm::dvec3 p, uint8_t cls, uint16_t intensity, uint8_t ret, uint16_t source,
              uint32_t color) {
  for (int k = 0; k < 3; ++k)
    c.positions.push_back(int32_t(std::llround((p[k] - c.offset[k]) / c.scale[k])));
  c.classification.push_back(cls);
  c.intensity.push_back(intensity);
  c.returnNumber.push_back(ret);
  c.pointSourceId.push_back(source);
  c.colors.push_back(color);
}

// Random points of class 2 or 6 in [0, 10]^2 x [0, 2] (the eight corners of that box in class 2), and two
// points on the ray of pixel (100, 40), which meets that slab beyond x = 10: the front one of class 6, the
// one behind of class 2, which also sets the bounds' maximum, so that the class-2 subset has the same
// bounds (and origin) as the whole.
TestCloud makeCloud() {
  TestCloud t;
  PointCloud& c = t.cloud;
  c.scale = glm::dvec3(0.001);
  c.offset = glm::dvec3(0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 8; ++i)
    addPoint(c, {i & 1 ? 10.0 : 0.0, i & 2 ? 10.0 : 0.0, i & 4 ? 2.0 : 0.0}, 2, 100, 1, 1,
             packRgba(200, 200, 200));
  for (int i = 0; i < 20000; ++i) {
    const glm::dvec3 p(10 * u(rng), 10 * u(rng), 2 * u(rng));
    addPoint(c, p, rng() % 2 ? 2 : 6, uint16_t(rng() % 4000), uint8_t(1 + rng() % 3), uint16_t(rng() % 5),
             packRgba(uint32_t(rng() % 256), uint32_t(rng() % 256), uint32_t(rng() % 256)));
  }
  const glm::dvec3 ray = pixelRay(100, 40);
  t.front = c.size();
  addPoint(c, kEye + ray * (29.0 / -ray.z), 6, 1234, 2, 17, packRgba(10, 20, 30)); // z = 1
  t.behind = c.size();
  addPoint(c, kEye + ray * (29.5 / -ray.z), 2, 4321, 3, 42, packRgba(40, 50, 60)); // z = 0.5
  computeBounds(c);
  return t;
}

std::string writeCloud(const PointCloud& cloud, const std::string& name) {
  const std::string path = (cliTempDir() / name).string();
  io::writeLas(path, cloud, io::LasFlavor::Las12Pf2);
  return path;
}

nlohmann::json renderJson(const std::string& args) {
  CliResult r = runPointrast("render " + args + " --json -q", {120});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  if (r.exitCode != 0) return {};
  return nlohmann::json::parse(r.out.substr(0, r.out.find('\n')));
}

} // namespace

TEST(RenderFilterCli, ClassFilterDrawsTheSubset) {
  const TestCloud t = makeCloud();
  const std::string all = writeCloud(t.cloud, "filter_all.las");
  PointCloud subset;
  subset.scale = t.cloud.scale;
  subset.offset = t.cloud.offset;
  for (size_t i = 0; i < t.cloud.size(); ++i)
    if (t.cloud.classification[i] == 2) {
      const glm::dvec3 p = t.cloud.world(i);
      addPoint(subset, p, 2, t.cloud.intensity[i], t.cloud.returnNumber[i], t.cloud.pointSourceId[i],
               t.cloud.colors[i]);
    }
  computeBounds(subset);
  ASSERT_EQ(subset.bounds.min, t.cloud.bounds.min);
  ASSERT_EQ(subset.bounds.max, t.cloud.bounds.max);
  const std::string part = writeCloud(subset, "filter_part.las");
  for (const char* method : {"atomicmin", "batch"}) {
    const std::string out = (cliTempDir() / "filter.png").string();
    const nlohmann::json filtered =
        renderJson(all + " -o " + out + " " + kCamera + " --method " + method + " --classes 2");
    const nlohmann::json reference = renderJson(part + " -o " + out + " " + kCamera + " --method " + method);
    const nlohmann::json unfiltered = renderJson(all + " -o " + out + " " + kCamera + " --method " + method);
    ASSERT_TRUE(filtered.contains("image_hash") && reference.contains("image_hash")) << method;
    EXPECT_EQ(filtered["image_hash"], reference["image_hash"]) << method;
    EXPECT_NE(filtered["image_hash"], unfiltered["image_hash"]) << method;
  }
}

// A generated scene carries its classes when a class filter or the classification colors ask for them:
// keeping every class the terrain has (ground, high vegetation, building) draws the whole scene; ground
// alone draws less; the classification colors are not the scene's own.
TEST(RenderFilterCli, GeneratedTerrainHasClassesToFilter) {
  const std::string out = (cliTempDir() / "terrain_classes.png").string();
  const std::string base = "terrain --points 50k --width 160 --height 120 -o " + out;
  const nlohmann::json whole = renderJson(base);
  const nlohmann::json every = renderJson(base + " --classes 2,5,6");
  const nlohmann::json ground = renderJson(base + " --classes 2");
  const nlohmann::json colored = renderJson(base + " --color classification");
  EXPECT_EQ(every["image_hash"], whole["image_hash"]);
  EXPECT_EQ(every["points"], whole["points"]);
  EXPECT_LT(ground["points"].get<uint64_t>(), whole["points"].get<uint64_t>());
  EXPECT_GT(ground["points"].get<uint64_t>(), whole["points"].get<uint64_t>() / 2);
  EXPECT_NE(ground["image_hash"], whole["image_hash"]);
  EXPECT_NE(colored["image_hash"], whole["image_hash"]);
}

TEST(RenderFilterCli, ClipBoxCullsBatchesInJson) {
  const TestCloud t = makeCloud();
  const std::string all = writeCloud(t.cloud, "filter_clip.las");
  const std::string out = (cliTempDir() / "clip.png").string();
  // Batches of the file's order are spread over the whole area, so --order morton makes them local: the
  // first of the two batches lies in the low half of x or y, which the box's corner does not reach.
  const nlohmann::json j = renderJson(all + " -o " + out + " " + kCamera +
                                      " --method batch --order morton --clip-box 9,9,0,10,10,2");
  ASSERT_TRUE(j.contains("batch_stats")) << j.dump();
  const nlohmann::json& b = j["batch_stats"];
  EXPECT_EQ(b["batches_processed"].get<uint64_t>(), 2u) << j.dump();
  EXPECT_EQ(b["batches_clipped"].get<uint64_t>(), 1u) << j.dump();
  EXPECT_EQ(b["batches_rendered"].get<uint64_t>(), 1u) << j.dump();
  const nlohmann::json plain =
      renderJson(all + " -o " + out + " " + kCamera + " --method batch --order morton");
  EXPECT_EQ(plain["batch_stats"]["batches_clipped"].get<uint64_t>(), 0u) << plain.dump();
}

TEST(RenderFilterCli, PickReportsTheClosestPointAtThePixel) {
  const TestCloud t = makeCloud();
  const std::string all = writeCloud(t.cloud, "filter_pick.las");
  const std::string out = (cliTempDir() / "pick.png").string();
  for (const char* method : {"atomicmin", "batch", "hqs"}) {
    const nlohmann::json j =
        renderJson(all + " -o " + out + " " + kCamera + " --method " + method + " --pick 100,40");
    ASSERT_TRUE(j.contains("pick")) << j.dump();
    const nlohmann::json& pick = j["pick"];
    EXPECT_EQ(pick["pixel"], nlohmann::json({100, 40}));
    if (std::string(method) == "hqs") {
      ASSERT_TRUE(pick["point"].is_string());
      EXPECT_EQ(pick["point"].get<std::string>().rfind("unavailable", 0), 0u) << pick.dump();
      continue;
    }
    ASSERT_TRUE(pick["point"].is_object()) << pick.dump();
    const nlohmann::json& p = pick["point"];
    const glm::dvec3 expected = t.cloud.world(t.front);
    EXPECT_NEAR(p["x"].get<double>(), expected.x, 1e-9) << method;
    EXPECT_NEAR(p["y"].get<double>(), expected.y, 1e-9) << method;
    EXPECT_NEAR(p["z"].get<double>(), expected.z, 1e-9) << method;
    EXPECT_EQ(p["classification"], 6) << method;
    EXPECT_EQ(p["intensity"], 1234) << method;
    EXPECT_EQ(p["return_number"], 2) << method;
    EXPECT_EQ(p["point_source_id"], 17) << method;
    EXPECT_EQ(p["color"], nlohmann::json({10, 20, 30})) << method;
  }
  // With the front point's class filtered out, the one behind it shows.
  const nlohmann::json behind = renderJson(all + " -o " + out + " " + kCamera + " --classes 2 --pick 100,40");
  ASSERT_TRUE(behind["pick"]["point"].is_object()) << behind.dump();
  EXPECT_EQ(behind["pick"]["point"]["intensity"], 4321);
  EXPECT_NEAR(behind["pick"]["point"]["z"].get<double>(), t.cloud.world(t.behind).z, 1e-9);
  // The corner of the image shows the background.
  const nlohmann::json none = renderJson(all + " -o " + out + " " + kCamera + " --pick 0,0");
  EXPECT_EQ(none["pick"]["point"], "none");
}

TEST(RenderFilterCli, BadPickAndMissingAttributesFailWithOneLine) {
  const TestCloud t = makeCloud();
  const std::string all = writeCloud(t.cloud, "filter_bad.las");
  const std::string out = (cliTempDir() / "bad.png").string();
  for (const std::string& args : {kCamera + " --pick 160,0 --json", kCamera + " --pick 3 --json",
                                  kCamera + " --pick 1,1", kCamera + " --gps-time 0,10 --json"}) {
    CliResult r = runPointrast("render " + all + " -o " + out + " -q " + args, {60});
    EXPECT_EQ(r.exitCode, 1) << args << "\n" << r.err;
    EXPECT_FALSE(r.signaled) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << args;
  }
}

} // namespace pointrast::test

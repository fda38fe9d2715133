// sphere-compute against the CPU ray caster (double precision, tests/oracles/cpu_spheres.h) and against
// the image contract:
// - a hand-built sphere: exact depth and color on the axis, background elsewhere, culling at the near plane;
// - random sets in every particle layout: >= 99 % of pixels agree (same hit, color within 1 per channel),
//   depth within 1e-5 relative where both hit away from the silhouette (see kGrazing);
// - a sphere crossing the image border, one filling most of the screen (large-sphere chunks, and the
//   overflow path when the chunk list is too small), overlapping and interpenetrating spheres;
// - global vs per-particle radius and color; several parts; frustum culling against brute force;
// - sphere centers land on the pixels where the point renderer puts the same positions.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "base/error.h"
#include "cloud/particles_generate.h"
#include "gpu/shared_types.h"
#include "render/renderer.h"
#include "spheres_test_util.h"

namespace pointrast::test {

TEST_F(GpuTest, SphereComputeHandBuiltContract) {
  // 65 x 65 pixels, 90 degrees: the ray of pixel (32, 32) is the axis (0, 0, -1). A sphere of radius 1 at
  // depth 5 is hit there at view depth exactly 4, facing the eye (full color); its disc has a radius of
  // tan(asin(1/5)) * 32.5 = 6.6 pixels, so the image corners are background.
  constexpr uint32_t kColor = 0xFF3264C8u; // r 200, g 100, b 50
  ParticleSet set = makeSet({{{0, 0, -5}, 1.0, kColor}});
  GpuFrame gpu = renderGpu(*context, set, axisCamera(), 65, 65);
  uint32_t center = 32 * 65 + 32;
  EXPECT_EQ(gpu.image[center], kColor);
  EXPECT_NEAR(gpu.depth[center], 4.0, 4.0 * 1e-6);
  EXPECT_EQ(gpu.index[center], 0u);
  for (uint32_t corner : {0u, 64u, 64u * 65u, 65u * 65u - 1u})
    EXPECT_EQ(gpu.image[corner], kBackground);
  // Seven pixels left of the center ray (-7 / 32.5 = 0.215 > 0.204): outside; six: inside.
  EXPECT_EQ(gpu.index[32 * 65 + 25], kNoParticle);
  EXPECT_EQ(gpu.index[32 * 65 + 26], 0u);
  expectAgreement("hand-built", gpu, renderCpu(set, axisCamera(), 65, 65));

  // The same sphere crossing the near plane (depth 0.5, radius 1; near 0.01) is culled whole, and so is
  // one behind the eye.
  ParticleSet crossing = makeSet({{{0, 0, -0.5}, 1.0, kColor}, {{0, 0, 5}, 1.0, kColor}});
  GpuFrame culled = renderGpu(*context, crossing, axisCamera(), 65, 65);
  EXPECT_TRUE(
      std::all_of(culled.index.begin(), culled.index.end(), [](uint32_t i) { return i == kNoParticle; }));
  EXPECT_TRUE(
      std::all_of(culled.image.begin(), culled.image.end(), [](uint32_t c) { return c == kBackground; }));
  SphereRaycast cpu = renderCpu(crossing, axisCamera(), 65, 65);
  EXPECT_TRUE(std::all_of(cpu.index.begin(), cpu.index.end(), [](uint32_t i) { return i == kNoParticle; }));
}

TEST_F(GpuTest, SphereComputeAgreesWithCpuInEveryLayout) {
  std::vector<SphereSpec> spheres = randomSpheres(3000, 7, 10, 0.05, 0.6);
  Camera camera = lookAt({-14, -20, 9}, {0, 0, 0});
  ParticleSet perParticle = makeSet(spheres);
  ParticleSet globalRadius = makeSet(spheres, true, false);
  ParticleSet globalBoth = makeSet(spheres, true, true);
  struct Case {
    const char* name;
    const ParticleSet* set;
    ParticleLayout layout;
  } cases[] = {{"soa8 per-particle", &perParticle, ParticleLayout::Soa8},
               {"vec4x2 per-particle", &perParticle, ParticleLayout::Vec4x2},
               {"soa8 global radius", &globalRadius, ParticleLayout::Soa8},
               {"aos global radius", &globalRadius, ParticleLayout::Aos},
               {"vec4x2 global radius and color", &globalBoth, ParticleLayout::Vec4x2},
               {"xyz global radius and color", &globalBoth, ParticleLayout::Xyz}};
  for (const Case& c : cases) {
    ParticleUploadOptions upload;
    upload.layout = c.layout;
    GpuFrame gpu = renderGpu(*context, *c.set, camera, 192, 128, upload);
    expectAgreement(c.name, gpu, renderCpu(*c.set, camera, 192, 128));
  }
}

TEST_F(GpuTest, SphereComputeLayoutsDrawTheSameSpheres) {
  // soa8 and vec4x2 hold the same floats: same visibility words, same image. aos and xyz differ only in
  // where radius and color come from, so the words (depth, index) are equal too.
  std::vector<SphereSpec> spheres = randomSpheres(2000, 11, 8, 0.1, 0.4);
  Camera camera = lookAt({-10, -14, 7}, {0, 0, 0});
  ParticleSet globalBoth = makeSet(spheres, true, true);
  std::vector<GpuFrame> frames;
  for (ParticleLayout layout :
       {ParticleLayout::Soa8, ParticleLayout::Vec4x2, ParticleLayout::Aos, ParticleLayout::Xyz}) {
    ParticleUploadOptions upload;
    upload.layout = layout;
    frames.push_back(renderGpu(*context, globalBoth, camera, 160, 120, upload));
  }
  for (size_t k = 1; k < frames.size(); ++k) {
    EXPECT_EQ(frames[k].index, frames[0].index) << particleLayoutName(particleLayoutTable()[k].layout);
    EXPECT_EQ(frames[k].depth, frames[0].depth) << particleLayoutName(particleLayoutTable()[k].layout);
  }
  EXPECT_EQ(frames[1].image, frames[0].image);
}

TEST_F(GpuTest, SphereComputeLayoutRefusesWhatItCannotHold) {
  ParticleSet perParticle = makeSet(randomSpheres(10, 1, 1, 0.1, 0.2));
  ParticleUploadOptions upload;
  upload.progress = false;
  upload.layout = ParticleLayout::Aos;
  EXPECT_THROW(GpuParticles(*context, perParticle, upload), InputError);
  upload.layout = ParticleLayout::Xyz;
  EXPECT_THROW(GpuParticles(*context, makeSet(randomSpheres(10, 1, 1, 0.1, 0.2), true, false), upload),
               InputError);
  EXPECT_EQ(compactLayout(perParticle), ParticleLayout::Vec4x2);
  EXPECT_EQ(compactLayout(makeSet(randomSpheres(10, 1, 1, 0.1, 0.2), true, false)), ParticleLayout::Aos);
  EXPECT_EQ(compactLayout(makeSet(randomSpheres(10, 1, 1, 0.1, 0.2), true, true)), ParticleLayout::Xyz);
}

TEST_F(GpuTest, SphereComputeGlobalAndPerParticleAttributesAgree) {
  // The same spheres with one radius and one color, stored once (xyz) or repeated per particle (vec4x2):
  // the same visibility words and image.
  std::vector<SphereSpec> spheres = randomSpheres(1500, 5, 6, 0.3, 0.3);
  for (SphereSpec& s : spheres)
    s.color = 0xFF20A0F0u;
  Camera camera = lookAt({-8, -11, 6}, {0, 0, 0});
  ParticleUploadOptions xyz, vec4;
  xyz.layout = ParticleLayout::Xyz;
  vec4.layout = ParticleLayout::Vec4x2;
  GpuFrame global = renderGpu(*context, makeSet(spheres, true, true), camera, 160, 120, xyz);
  GpuFrame each = renderGpu(*context, makeSet(spheres), camera, 160, 120, vec4);
  EXPECT_EQ(global.index, each.index);
  EXPECT_EQ(global.depth, each.depth);
  EXPECT_EQ(global.image, each.image);
  expectAgreement("global radius and color", global,
                  renderCpu(makeSet(spheres, true, true), camera, 160, 120));
}

TEST_F(GpuTest, SphereComputeSphereAcrossTheImageBorder) {
  // A sphere centered on the left border and one on the bottom-right corner (90 degrees vertically, so
  // at depth 5 the image spans x in +-5 * 4/3 and y in +-5): each is cut by the image edge, and the
  // pixels along the edge are covered.
  ParticleSet set =
      makeSet({{{-5 * 4.0 / 3, 0, -5}, 1.5, 0xFF0000FFu}, {{5 * 4.0 / 3, -5, -5}, 1.2, 0xFF00FF00u}});
  Camera camera = axisCamera();
  camera.fovY = 90;
  GpuFrame gpu = renderGpu(*context, set, camera, 160, 120);
  SphereRaycast cpu = renderCpu(set, camera, 160, 120, true);
  expectAgreement("border", gpu, cpu);
  EXPECT_EQ(gpu.index[60 * 160 + 0], 0u);    // left column, middle row
  EXPECT_EQ(gpu.index[119 * 160 + 159], 1u); // bottom-right pixel
}

TEST_F(GpuTest, SphereComputeLargeSphereUsesChunksAndSurvivesAFullList) {
  // A sphere filling most of the screen (its box is about 130 x 120 pixels: about 60 chunks) in front of
  // many small ones, some of which poke out around it, and a medium one in front of it (a few chunks).
  std::vector<SphereSpec> spheres = randomSpheres(500, 3, 3, 0.05, 0.2);
  for (SphereSpec& s : spheres)
    s.center.z -= 6;
  spheres.push_back({{0.2, -0.1, -3}, 1.8, 0xFFC0C0C0u});
  spheres.push_back({{-0.5, 0.3, -1.0}, 0.15, 0xFF4080FFu});
  ParticleSet set = makeSet(spheres);
  Camera camera = axisCamera();
  camera.fovY = 70;
  GpuFrame gpu = renderGpu(*context, set, camera, 160, 120);
  SphereRaycast cpu = renderCpu(set, camera, 160, 120);
  expectAgreement("large sphere", gpu, cpu);
  EXPECT_GT(gpu.stats.largeChunks, 50u);
  EXPECT_GT(std::count(gpu.index.begin(), gpu.index.end(), uint32_t(spheres.size() - 1)), 100);
  EXPECT_EQ(gpu.stats.spilledSpheres, 0u);
  size_t big = std::count(gpu.index.begin(), gpu.index.end(), uint32_t(spheres.size() - 2));
  EXPECT_GT(big, 160u * 120u / 2) << "the big sphere should cover more than half the image";

  // A list of 10 chunks: the big sphere's chunks past the 10th are drawn by its own thread; the result is
  // the same frame.
  SphereSettings small;
  small.chunkCapacity = 10;
  GpuFrame spilled = renderGpu(*context, set, camera, 160, 120, {}, small);
  EXPECT_GE(spilled.stats.spilledSpheres, 1u);
  EXPECT_EQ(spilled.stats.largeChunks, 10u);
  EXPECT_EQ(spilled.index, gpu.index);
  EXPECT_EQ(spilled.depth, gpu.depth);
  EXPECT_EQ(spilled.image, gpu.image);
}

TEST_F(GpuTest, SphereComputeOverlappingSpheresKeepDepthOrder) {
  // Disjoint in depth: the nearer red sphere hides part of the green one behind it, whichever comes
  // first in the set. Interpenetrating: blue and yellow of equal size cut each other along a circle.
  for (bool nearFirst : {true, false}) {
    std::vector<SphereSpec> spheres = {{{-1, 0.3, -6}, 1.0, 0xFF0000FFu},
                                       {{-0.4, 0, -9}, 1.5, 0xFF00FF00u},
                                       {{1.2, -0.5, -7}, 1.0, 0xFFFF0000u},
                                       {{2.0, -0.5, -7.4}, 1.0, 0xFF00FFFFu}};
    if (!nearFirst) std::swap(spheres[0], spheres[1]);
    ParticleSet set = makeSet(spheres);
    Camera camera = axisCamera();
    camera.fovY = 60;
    GpuFrame gpu = renderGpu(*context, set, camera, 160, 120);
    SphereRaycast cpu = renderCpu(set, camera, 160, 120);
    expectAgreement(nearFirst ? "overlap, near first" : "overlap, far first", gpu, cpu);
    uint32_t red = nearFirst ? 0 : 1, green = nearFirst ? 1 : 0;
    // The red sphere's center pixel: the ray through it also hits green, farther away.
    glm::dvec3 c = spheres[red].center;
    double tanY = std::tan(glm::radians(30.0)), tanX = tanY * 160 / 120;
    uint32_t px = uint32_t((c.x / -c.z / tanX + 1) / 2 * 160),
             py = uint32_t((1 - c.y / -c.z / tanY) / 2 * 120);
    EXPECT_EQ(gpu.index[py * 160 + px], red);
    EXPECT_GT(std::count(gpu.index.begin(), gpu.index.end(), green), 100);
    // Both interpenetrating spheres are visible, each with the CPU's winner on the cut.
    EXPECT_GT(std::count(gpu.index.begin(), gpu.index.end(), 2u), 100);
    EXPECT_GT(std::count(gpu.index.begin(), gpu.index.end(), 3u), 100);
  }
}

TEST_F(GpuTest, SphereComputeFrustumCullingNeverDropsAVisibleSphere) {
  // Spheres whose centers are outside the view frustum (left, right, above, below) but which reach a
  // few pixels into the image, spheres just outside it, behind the eye, and crossing the near plane;
  // against the brute-force CPU ray caster, which tests every sphere at every pixel.
  Camera camera = axisCamera(); // 90 degrees, near 0.01
  // Radii of 0.6 to 6 pixels whatever the depth.
  std::vector<SphereSpec> spheres = frustumEdgeSpheres(0.1);
  spheres.push_back({{0, 0, 3}, 1, 0xFFFFFFFFu});          // behind the eye
  spheres.push_back({{0.3, 0.2, -0.5}, 0.6, 0xFFFFFFFFu}); // crossing the near plane
  ParticleSet set = makeSet(spheres);
  GpuFrame gpu = renderGpu(*context, set, camera, 160, 120);
  SphereRaycast cpu = renderCpu(set, camera, 160, 120, true);
  expectAgreement("frustum edges", gpu, cpu);
  std::vector<bool> seenGpu(spheres.size()), seenCpu(spheres.size());
  for (size_t i = 0; i < gpu.index.size(); ++i) {
    if (gpu.index[i] != kNoParticle) seenGpu[gpu.index[i]] = true;
    if (cpu.index[i] != kNoParticle) seenCpu[cpu.index[i]] = true;
  }
  size_t visible = std::count(seenCpu.begin(), seenCpu.end(), true);
  EXPECT_GT(visible, 100u) << "the scene should put many spheres across the image edges";
  // A sphere the CPU sees on at least two pixels must be seen by the GPU (a single pixel may be lost to
  // rounding at the silhouette).
  std::vector<int> cpuPixels(spheres.size());
  for (uint32_t i : cpu.index)
    if (i != kNoParticle) ++cpuPixels[i];
  for (size_t s = 0; s < spheres.size(); ++s)
    if (cpuPixels[s] >= 2) {
      EXPECT_TRUE(seenGpu[s]) << "sphere " << s << " visible on " << cpuPixels[s] << " pixels";
    }
  EXPECT_FALSE(seenGpu[spheres.size() - 2]);
  EXPECT_FALSE(seenGpu[spheres.size() - 1]);
  EXPECT_FALSE(seenCpu[spheres.size() - 1]);
}

TEST_F(GpuTest, SphereComputeManyPartsDrawTheSameFrame) {
  // UTM-like coordinates: the set's float offsets are relative to its origin, and the camera too.
  const glm::dvec3 utm(500000.25, 4200000.5, 30);
  std::vector<SphereSpec> spheres = randomSpheres(2000, 13, 8, 0.1, 0.5);
  spheres.push_back({{0, 0, 0}, 3.0, 0xFFFFFFFFu}); // a large sphere in the last part
  for (SphereSpec& s : spheres)
    s.center += utm;
  ParticleSet set = makeSet(spheres, false, false, utm);
  Camera camera = lookAt(utm + glm::dvec3(-12, -16, 10), utm);
  GpuFrame one = renderGpu(*context, set, camera, 160, 120);
  ParticleUploadOptions parts;
  parts.maxPartParticles = 3 * 128;
  GpuFrame many = renderGpu(*context, set, camera, 160, 120, parts);
  EXPECT_EQ(many.index, one.index);
  EXPECT_EQ(many.depth, one.depth);
  EXPECT_EQ(many.image, one.image);
  EXPECT_GT(std::count(one.index.begin(), one.index.end(), uint32_t(spheres.size() - 1)), 50);
  expectAgreement("UTM origin, 6 parts", many, renderCpu(set, camera, 160, 120));
}

TEST_F(GpuTest, SphereCentersLandWhereThePointRendererPutsThem) {
  // The camera convention is the point renderer's: spheres of radius well above a pixel cover the pixel
  // where atomicmin draws their centers as points, and nothing else is lit there.
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<SphereSpec> spheres;
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  for (int i = 0; i < 60; ++i) {
    glm::dvec3 c{u(rng) * 9, u(rng) * 6, u(rng) * 2};
    spheres.push_back({c, 0.3, 0xFF000000u | uint32_t(i)});
    points.push_back(c);
    colors.push_back(0xFF000000u | uint32_t(i));
  }
  Camera camera = lookAt({-6, -15, 8}, {0, 0, 0}, 50);
  PointCloud cloud = cloudFromPoints(points, colors, 1e-6);
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(*context, cloud, upload);
  Renderer pointRenderer(*context, 200, 150);
  RenderSettings settings;
  settings.captureWords = true;
  pointRenderer.render(scene, camera, settings);
  std::vector<uint64_t> words = pointRenderer.framebufferWords();
  GpuFrame spheresFrame = renderGpu(*context, makeSet(spheres), camera, 200, 150);
  int checked = 0;
  for (size_t p = 0; p < words.size(); ++p) {
    if (words[p] == shared::kEmptyPixel) continue;
    uint32_t point = uint32_t(words[p]) & 0xFFFFFFu;
    // Some sphere covers every pixel of a center (spheres are 2.7 pixels in radius or more); it is that
    // sphere unless a nearer one hides its center.
    ASSERT_NE(spheresFrame.index[p], kNoParticle) << "pixel " << p << " of point " << point;
    if (spheresFrame.index[p] == point) ++checked;
  }
  EXPECT_GE(checked, 50);
}

} // namespace pointrast::test

namespace pointrast::test {
namespace {

// The first camera of the spheres2023 suite's short orbit (bench/views.cpp): inside the bounds, at half
// their extent along x and y from the center, a quarter of the half height above it, looking at it.
Camera shortOrbitCamera(const Bounds& bounds) {
  const glm::dvec3 center = bounds.center(), half = 0.5 * (bounds.max - bounds.min);
  const double angle = 1.25 * std::numbers::pi;
  Camera camera;
  camera.eye =
      center + glm::dvec3(0.5 * half.x * std::cos(angle), 0.5 * half.y * std::sin(angle), 0.25 * half.z);
  camera.target = center;
  camera.up = {0, 0, 1};
  camera.fovY = 60;
  return camera;
}

} // namespace

TEST_F(GpuTest, SphereComputeTileBoundsSkipHiddenLargeSpheresAndKeepTheFrame) {
  // A Riemann-like block seen from inside, as the suite's short orbit sees it: spheres near the eye cover
  // whole tiles, and most large spheres behind them are hidden. The tile depth bounds must leave the frame
  // bit for bit as it is without them, and cut the work of the large-sphere pass.
  ParticleGenerateOptions options;
  options.particles = 200'000;
  options.progress = false;
  const ParticleSet set = generateParticles(ParticleScene::Block, options);
  const Camera camera = shortOrbitCamera(set.bounds);
  // Every large sphere cut along tiles first (at this size most are mid-size, which the default cuts into
  // bands of box rows), so that the bounds have the most to skip.
  SphereSettings settings;
  settings.countWork = true;
  settings.tileCutPixels = shared::kSphereSmallPixels;
  settings.occlusionCull = false; // which would drop hidden spheres before they list chunks
  GpuFrame bounded = renderGpu(*context, set, camera, 320, 240, {}, settings);
  settings.tileBound = false;
  GpuFrame unbounded = renderGpu(*context, set, camera, 320, 240, {}, settings);
  std::printf(
      "riemann-like short orbit, 200 k spheres, 320x240, with / without tile bounds: large chunks %llu, "
      "skipped %llu / %llu; pixels tested in large chunks %llu / %llu, in all %llu / %llu; depth "
      "atomics %llu / %llu\n",
      (unsigned long long)bounded.stats.largeChunks, (unsigned long long)bounded.stats.skippedChunks,
      (unsigned long long)unbounded.stats.skippedChunks, (unsigned long long)bounded.stats.largePixelsTested,
      (unsigned long long)unbounded.stats.largePixelsTested, (unsigned long long)bounded.stats.pixelsTested,
      (unsigned long long)unbounded.stats.pixelsTested, (unsigned long long)bounded.stats.depthAtomics,
      (unsigned long long)unbounded.stats.depthAtomics);
  EXPECT_EQ(bounded.index, unbounded.index);
  EXPECT_EQ(bounded.depth, unbounded.depth);
  EXPECT_EQ(bounded.image, unbounded.image);
  // The default cut (bands for mid-size spheres) and bands wherever a band fits: the same frame again,
  // from fewer listed chunks.
  for (uint32_t cut : {0u, 1u << 30}) {
    settings.tileBound = true;
    settings.tileCutPixels = cut;
    GpuFrame recut = renderGpu(*context, set, camera, 320, 240, {}, settings);
    EXPECT_EQ(recut.index, bounded.index) << "tiles above " << cut << " pixels";
    EXPECT_EQ(recut.depth, bounded.depth) << "tiles above " << cut << " pixels";
    EXPECT_EQ(recut.image, bounded.image) << "tiles above " << cut << " pixels";
    EXPECT_LT(recut.stats.largeChunks, bounded.stats.largeChunks) << "tiles above " << cut << " pixels";
  }
  EXPECT_GT(std::count_if(bounded.index.begin(), bounded.index.end(),
                          [](uint32_t i) { return i != shared::kNoParticle; }),
            320 * 240 * 9 / 10)
      << "the block should fill the image";
  EXPECT_EQ(bounded.stats.largeChunks, unbounded.stats.largeChunks);
  EXPECT_EQ(unbounded.stats.skippedChunks, 0u);
  EXPECT_GT(bounded.stats.skippedChunks, bounded.stats.largeChunks / 2);
  EXPECT_LT(bounded.stats.largePixelsTested * 2, unbounded.stats.largePixelsTested);
  EXPECT_LT(bounded.stats.pixelsTested, unbounded.stats.pixelsTested);
  EXPECT_LE(bounded.stats.depthAtomics, unbounded.stats.depthAtomics);
}

} // namespace pointrast::test

namespace pointrast::test {

// Not a check: the work counts behind the choice of kSphereTileCutPixels (docs/performance.md), printed per
// threshold for generated riemann-like and laser-like scenes on the short orbit's first camera, scaled so
// that spheres cover about as many pixels as in the spheres2023 suite at full scale (1920x1080). Run with
// --gtest_also_run_disabled_tests; about two minutes on lavapipe (2 cores).
TEST_F(GpuTest, DISABLED_SphereComputeWorkByTileCut) {
  struct Case {
    const char* name;
    ParticleScene scene;
    uint64_t particles;
    uint32_t width, height;
  } cases[] = {{"riemann-like", ParticleScene::Block, 200'000, 640, 360},
               {"riemann-like", ParticleScene::Block, 1'000'000, 1280, 720},
               {"laser-like", ParticleScene::Laser, 1'000'000, 1280, 720}};
  for (const Case& c : cases) {
    ParticleGenerateOptions options;
    options.particles = c.particles;
    options.progress = false;
    const ParticleSet set = generateParticles(c.scene, options);
    ParticleUploadOptions upload;
    upload.progress = false;
    GpuParticles particles(*context, set, upload);
    SphereRenderer renderer(*context, c.width, c.height);
    std::vector<uint32_t> reference;
    const SphereRaycast cpu = c.particles <= 1'000'000
                                  ? renderCpu(set, shortOrbitCamera(set.bounds), c.width, c.height)
                                  : SphereRaycast{};
    // The first threshold again last: whether this lavapipe renders the frame reproducibly at that size.
    for (uint32_t cut : {64u, 256u, 576u, 1024u, 2304u, 4096u, 16384u, 65536u, 64u}) {
      SphereSettings settings;
      settings.countWork = true;
      settings.tileCutPixels = cut;
      const SphereStats stats = renderer.render(particles, shortOrbitCamera(set.bounds), settings);
      std::printf("| %s %llu k, %ux%u | %u | %llu | %llu | %llu | %llu | %llu |", c.name,
                  (unsigned long long)(c.particles / 1000), c.width, c.height, cut,
                  (unsigned long long)stats.largeChunks, (unsigned long long)stats.skippedChunks,
                  (unsigned long long)stats.largePixelsTested, (unsigned long long)stats.pixelsTested,
                  (unsigned long long)stats.depthAtomics);
      // Frames that differ between thresholds, or from the CPU ray caster beyond a few silhouette pixels
      // (float against double), would void the counts.
      std::vector<uint32_t> indices = renderer.indices();
      if (reference.empty()) reference = indices;
      size_t differing = 0;
      for (size_t p = 0; p < indices.size(); ++p)
        differing += indices[p] != reference[p];
      size_t offCpu = 0;
      for (size_t p = 0; p < cpu.index.size(); ++p)
        offCpu += indices[p] != cpu.index[p];
      std::printf("  (%zu pixels differ from the first row's frame, %zu from the CPU's)\n", differing,
                  offCpu);
      EXPECT_EQ(differing, 0u) << c.name << ", tiles above " << cut << " pixels";
      EXPECT_LE(offCpu, indices.size() / 10000) << c.name << ", tiles above " << cut << " pixels";
    }
    // Without the bounds every listed chunk is drawn: 875 k on the 1 M frame with tiles everywhere, more
    // than llvmpipe's loop limit lets 8 workgroups draw (8 x 65535), so this checks the draw pass's grid.
    SphereSettings unbounded;
    unbounded.tileBound = false;
    unbounded.tileCutPixels = shared::kSphereSmallPixels;
    renderer.render(particles, shortOrbitCamera(set.bounds), unbounded);
    EXPECT_EQ(renderer.indices(), reference) << c.name << ", without bounds";
  }
}

} // namespace pointrast::test

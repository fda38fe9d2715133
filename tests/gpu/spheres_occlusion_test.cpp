// sphere-compute's occlusion culling of particle batches (shaders/sphere_batch_cull.comp.glsl): the frame
// must be bit for bit the frame without it, in every layout, whatever the last frame's view left in the
// batches' flags, and a dense set seen from outside must leave most batches undrawn.
#include <algorithm>
#include <numbers>

#include "cloud/order.h"
#include "cloud/particles_generate.h"
#include "gpu/shared_types.h"
#include "spheres_test_util.h"

namespace pointrast::test {

namespace {

GpuFrame renderWith(SphereRenderer& renderer, const GpuParticles& particles, const Camera& camera, bool cull,
                    uint32_t warmup = 1) {
  SphereSettings settings;
  settings.occlusionCull = cull;
  settings.warmup = warmup;
  return renderFrame(renderer, particles, camera, settings);
}

void expectSameFrame(const GpuFrame& culled, const GpuFrame& reference, const std::string& what) {
  size_t differing = 0;
  for (size_t p = 0; p < reference.index.size(); ++p)
    differing += culled.index[p] != reference.index[p];
  EXPECT_EQ(differing, 0u) << what << ": pixels whose sphere differs";
  EXPECT_TRUE(culled.depth == reference.depth) << what;
  EXPECT_TRUE(culled.image == reference.image) << what;
}

Camera orbit(const Bounds& bounds, double angle, double distance, double elevation) {
  const glm::dvec3 center = bounds.center();
  const double radius = 0.5 * glm::length(bounds.max - bounds.min);
  Camera camera;
  camera.eye = center + distance * radius *
                            glm::dvec3(std::cos(elevation) * std::cos(angle),
                                       std::cos(elevation) * std::sin(angle), std::sin(elevation));
  camera.target = center;
  camera.up = {0, 0, 1};
  camera.fovY = 60;
  return camera;
}

} // namespace

TEST_F(GpuTest, SphereOcclusionCullingKeepsTheFrameInEveryLayout) {
  std::vector<SphereSpec> spheres = randomSpheres(6000, 23, 6, 0.1, 0.5);
  Camera camera = lookAt({-9, -12, 6}, {0, 0, 0});
  struct Case {
    const char* name;
    ParticleSet set;
    ParticleLayout layout;
  } cases[] = {{"soa8", makeSet(spheres), ParticleLayout::Soa8},
               {"vec4x2", makeSet(spheres), ParticleLayout::Vec4x2},
               {"aos", makeSet(spheres, true, false), ParticleLayout::Aos},
               {"xyz", makeSet(spheres, true, true), ParticleLayout::Xyz}};
  for (const Case& c : cases) {
    ParticleUploadOptions upload;
    upload.progress = false;
    upload.layout = c.layout;
    upload.maxPartParticles = 1000; // parts that end inside a batch
    GpuParticles particles(*context, c.set, upload);
    SphereRenderer renderer(*context, 200, 150);
    GpuFrame reference = renderWith(renderer, particles, camera, false);
    // The first frame after the upload draws every batch first; the later ones only the visible.
    for (uint32_t warmup : {0u, 1u, 3u})
      expectSameFrame(renderWith(renderer, particles, camera, true, warmup), reference,
                      std::string(c.name) + ", " + std::to_string(warmup) + " frames before");
  }
}

TEST_F(GpuTest, SphereOcclusionCullingDropsHiddenBatchesOfADenseSetAndKeepsTheFrame) {
  // A riemann-like set (a lattice block stored row by row, between two vapor regions), seen from outside:
  // the rows inside the block are hidden behind its faces. Views change between renders, so each frame
  // starts from the flags another view left.
  ParticleGenerateOptions options;
  options.particles = 1'000'000;
  options.progress = false;
  const ParticleSet set = generateParticles(ParticleScene::Block, options);
  ParticleUploadOptions upload;
  upload.progress = false;
  GpuParticles particles(*context, set, upload);
  SphereRenderer renderer(*context, 480, 300);
  const double kDegree = std::numbers::pi / 180;
  // Distances in radii of the bounds, which the vapor stretches along x: at 0.5 the eye is outside the
  // block, which fills much of the image.
  struct View {
    double angle, distance, elevation;
  } views[] = {{0, 0.5, 20 * kDegree},  {90 * kDegree, 0.5, 20 * kDegree}, {200 * kDegree, 0.9, 60 * kDegree},
               {0, 0.5, 20 * kDegree},  {45 * kDegree, 0.1, 10 * kDegree}, {300 * kDegree, 1.2, -30 * kDegree}};
  uint64_t batches = 0, visible = 0;
  for (const View& v : views) {
    const Camera camera = orbit(particles.bounds(), v.angle, v.distance, v.elevation);
    GpuFrame reference = renderWith(renderer, particles, camera, false);
    GpuFrame culled = renderWith(renderer, particles, camera, true, 0);
    expectSameFrame(culled, reference, "view at " + std::to_string(v.angle / kDegree) + " degrees");
    // Twice in a row: the second frame draws the batches the first found visible.
    GpuFrame again = renderWith(renderer, particles, camera, true, 1);
    expectSameFrame(again, reference, "again at " + std::to_string(v.angle / kDegree) + " degrees");
    EXPECT_EQ(again.stats.batches, (particles.count() + shared::kSphereBatchSize - 1) / shared::kSphereBatchSize);
    EXPECT_LE(again.stats.visibleBatches, again.stats.batches);
    if (v.distance == 0.5) {
      batches += again.stats.batches;
      visible += again.stats.visibleBatches;
    }
    std::printf("view %.0f deg, distance %.1f: %llu of %llu batches visible, %llu drawn late\n",
                v.angle / kDegree, v.distance, (unsigned long long)again.stats.visibleBatches,
                (unsigned long long)again.stats.batches, (unsigned long long)again.stats.lateBatches);
  }
  // From outside at 20 degrees above the block, most of it is hidden.
  EXPECT_LT(visible * 3, batches);
}

TEST(SphereSpatialOrder, IsAStablePermutationInMortonOrderOfCells) {
  std::vector<SphereSpec> spheres = randomSpheres(50'000, 3, 20, 0.1, 0.2);
  for (size_t i = 0; i < 1000; ++i) // duplicates: equal cells keep the set's order
    spheres.push_back(spheres[i]);
  ParticleSet set = makeSet(spheres);
  std::vector<uint32_t> order = spatialOrder(set);
  ASSERT_EQ(order.size(), set.size());
  std::vector<bool> seen(set.size());
  for (uint32_t i : order) {
    ASSERT_LT(i, set.size());
    EXPECT_FALSE(seen[i]) << "particle " << i << " twice";
    seen[i] = true;
  }
  // Consecutive particles are near each other: the mean step is a small fraction of the extent.
  double step = 0;
  for (size_t k = 1; k < order.size(); ++k)
    step += glm::length(set.world(order[k]) - set.world(order[k - 1]));
  step /= double(order.size() - 1);
  EXPECT_LT(step, 0.05 * glm::length(set.bounds.max - set.bounds.min));
  // A duplicate follows its original directly or after other particles of the same cell, never before.
  std::vector<size_t> position(set.size());
  for (size_t k = 0; k < order.size(); ++k)
    position[order[k]] = k;
  for (size_t i = 0; i < 1000; ++i)
    EXPECT_LT(position[i], position[50'000 + i]);
}

} // namespace pointrast::test

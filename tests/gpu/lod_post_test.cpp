// The LOD methods with the resolve stage and coloring by attribute:
// - lod and lod-hqs frames with point size, dilation and eye-dome lighting equal the stage run on their own
//   words (the image of the same frame without it), in one pass and in passes through a small node cache;
// - each color mode colors the point that wins a pixel as the attribute's palette or ramp says (the winner
//   of a pixel does not depend on colors, so a frame whose colors name points tells which one it is).
#include <cstring>
#include <random>

#include "cloud/attribute_colors.h"
#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu_fixture.h"
#include "lod_octree.h"
#include "render/lod/lod_scene.h"
#include "render/post/post_stage.h"
#include "render/renderer.h"

namespace pointrast::test {

namespace {

constexpr uint32_t kWidth = 96, kHeight = 64;

struct Frame {
  std::vector<uint32_t> image;
  std::vector<uint64_t> words;
  FrameStats stats;
};

lod::LodOptions options(uint64_t gpuBytes) {
  lod::LodOptions o;
  o.gpuBytes = gpuBytes;
  o.readers = 2;
  o.stagingBytes = 8ull << 20;
  return o;
}

RenderSettings settingsFor(const char* method, const PostSettings& post) {
  RenderSettings s;
  s.method = parseMethod(method);
  s.minNodePx = 0;
  s.background = 0xFF000000u;
  s.frames = 1;
  s.warmup = 0;
  s.post = post;
  s.captureWords = true;
  return s;
}

Frame drawLod(gpu::Context& context, lod::NodeSource& tree, const Camera& camera, const RenderSettings& s,
              const lod::LodOptions& o = options(64ull << 20)) {
  Renderer renderer(context, kWidth, kHeight);
  lod::LodScene scene(context, tree, o);
  Frame f;
  f.stats = renderer.render(scene, camera, s);
  f.image = renderer.image();
  f.words = renderer.framebufferWords();
  return f;
}

// The stage run on words alone (PostStage, as the renderer runs it after a method).
std::vector<uint32_t> postOf(gpu::Context& context, const std::vector<uint64_t>& words,
                             const PostSettings& post, float referenceDepth) {
  gpu::Buffer in(context, words.size() * 8, gpu::kBufferUsage, gpu::MemoryKind::Upload, "words");
  std::memcpy(in.mapped(), words.data(), words.size() * 8);
  gpu::Buffer image(context, words.size() * 4, gpu::kBufferUsage, gpu::MemoryKind::Readback, "image");
  PostStage stage(context);
  PostView view{in.address(), image.address(), kWidth, kHeight, kWidth, referenceDepth, 0xFF000000u, false};
  context.submitAndWait([&](VkCommandBuffer cmd) { stage.record(cmd, view, post); });
  image.invalidate();
  const auto* p = static_cast<const uint32_t*>(image.mapped());
  return {p, p + words.size()};
}

// A sparse box: holes for the dilation to fill, depth steps for eye-dome lighting.
void sparseOctree(MemoryOctree& tree) {
  std::mt19937_64 rng(16);
  buildOctree(tree, randomBoxCloud(rng, 20'000, {20, 10, 5}), 1500);
}

size_t filled(const std::vector<uint64_t>& words) {
  size_t n = 0;
  for (uint64_t w : words)
    n += w != shared::kEmptyPixel;
  return n;
}

size_t lit(const std::vector<uint32_t>& image) {
  size_t n = 0;
  for (uint32_t c : image)
    n += c != 0xFF000000u;
  return n;
}

} // namespace

TEST_F(GpuTest, LodFramesWithTheResolveStageEqualTheStageOnTheirWords) {
  MemoryOctree tree;
  sparseOctree(tree);
  const PointCloud all = tree.cloud();
  const Camera camera = overviewCamera(all.bounds, double(kWidth) / kHeight);
  const float reference = float(glm::length(camera.target - camera.eye));
  PostSettings square;
  square.pointSize = 3;
  square.dilate = 2;
  square.edlStrength = 1;
  PostSettings attenuated;
  attenuated.pointSize = 2;
  attenuated.sizeMode = PointSizeMode::Attenuated;
  attenuated.shape = PointShape::Disc;
  // A fixed size that rounds to one pixel runs the stage without changing a word: lod-hqs keeps no words
  // of its own otherwise.
  PostSettings identity;
  identity.pointSize = 1.25f;
  for (const char* method : {"lod", "lod-hqs"}) {
    const Frame plain = drawLod(*context, tree, camera, settingsFor(method, identity));
    ASSERT_TRUE(plain.stats.post) << method;
    EXPECT_GT(lit(plain.image), 1000u) << method;
    for (const PostSettings& post : {square, attenuated}) {
      const Frame withPost = drawLod(*context, tree, camera, settingsFor(method, post));
      ASSERT_TRUE(withPost.stats.post) << method;
      EXPECT_EQ(withPost.image, postOf(*context, plain.words, post, reference)) << method;
      // Eye-dome lighting may shade a pixel to the background's black: count the words.
      EXPECT_GT(filled(withPost.words), filled(plain.words)) << method << ": larger points and filled holes";
      // Through a node cache of a few pages: the selection drawn in passes, the stage after the last.
      const Frame passes =
          drawLod(*context, tree, camera, settingsFor(method, post), options(8 * shared::kLodPageBytes));
      EXPECT_GT(passes.stats.lod->passes, 1u) << method;
      EXPECT_EQ(passes.image, withPost.image) << method;
    }
  }
}

TEST_F(GpuTest, LodColorModesColorEachPixelsWinnerByItsAttribute) {
  MemoryOctree tree;
  sparseOctree(tree);
  tree.colorsAreIndices();
  tree.meta.fields.classification = tree.meta.fields.intensity = true;
  std::vector<const PointRecord*> byIndex; // point i + 1 of the colors that name points
  for (auto& [key, records] : tree.nodes)
    for (PointRecord& r : records) {
      r.classification = uint8_t((uint32_t(r.x) / 997u) % 10u);
      r.intensity = uint16_t(uint32_t(r.y) % 4001u);
      byIndex.push_back(&r);
    }
  const PointCloud all = tree.cloud();
  const Camera camera = overviewCamera(all.bounds, double(kWidth) / kHeight);
  RenderSettings s = settingsFor("lod", {});
  s.captureWords = true;
  const Frame named = drawLod(*context, tree, camera, s);
  ASSERT_GT(lit(named.image), 1000u);
  auto check = [&](const lod::LodOptions& o, auto expected, const char* mode) {
    const Frame colored = drawLod(*context, tree, camera, s, o);
    size_t compared = 0;
    for (size_t i = 0; i < named.image.size(); ++i) {
      const uint32_t index = named.image[i] & 0xFFFFFFu;
      if (named.words[i] == shared::kEmptyPixel) {
        EXPECT_EQ(colored.image[i], 0xFF000000u) << mode;
        continue;
      }
      ASSERT_GE(index, 1u);
      ASSERT_LE(index, byIndex.size());
      ASSERT_EQ(colored.image[i], expected(*byIndex[index - 1])) << mode << " pixel " << i;
      ++compared;
    }
    EXPECT_GT(compared, 1000u) << mode;
  };
  lod::LodOptions o = options(64ull << 20);
  o.colorSource = DisplayColorMode::Source::Classification;
  check(
      o, [](const PointRecord& r) { return classificationColor(r.classification); }, "classification");
  o.colorSource = DisplayColorMode::Source::Intensity;
  o.colorRange = ColorRange{1000, 3000};
  check(
      o, [](const PointRecord& r) { return intensityColor((r.intensity - 1000.0) / 2000.0); }, "intensity");
  // An attribute the octree lacks is one clear error naming it.
  o.colorSource = DisplayColorMode::Source::PointSource;
  o.colorRange.reset();
  try {
    Renderer renderer(*context, kWidth, kHeight);
    lod::LodScene scene(*context, tree, o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("memory octree"), std::string::npos) << e.what();
  }
}

} // namespace pointrast::test

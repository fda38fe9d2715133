// The resolve stage (src/render/post) against independent CPU computations, on hand-built scenes whose
// points sit on pixel centers (so a pixel is never a matter of rounding):
// - points of size N: the image equals a CPU rasterization of squares or discs with a depth test, for a
//   closest-point method, a batch method, HQS and int40 depth; fixed and attenuated sizes;
// - dilation fills a one-pixel hole in a flat surface, never lets a far point cover a near one, leaves
//   silhouettes alone, and equals a CPU implementation of its rule word for word;
// - eye-dome lighting equals a CPU implementation of Potree's formula within 1 per channel;
// - each color mode maps a hand-built cloud to the expected colors, uploaded or recolored;
// - the stage run on a window of a wider buffer (one eye of a stereo image) equals the stage run alone.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>

#include "base/error.h"
#include "cloud/attribute_colors.h"
#include "gpu/shader_registry.h"
#include "gpu/shared_types.h"
#include "gpu/spirv_reflect.h"
#include "gpu_fixture.h"
#include "render/post/post_stage.h"
#include "render/renderer.h"

namespace pointrast::test {

namespace {

constexpr uint32_t kSide = 48; // square images: axisCamera's formula holds for aspect 1
constexpr uint32_t kBackground = 0xFF201008u;

// A point on the center of pixel (px, py) at linear depth `depth`.
struct Dot {
  int px, py;
  double depth;
  uint32_t color;
};

glm::dvec3 onPixel(int px, int py, double depth, uint32_t side = kSide) {
  // axisCamera: px = floor((x/d + 1) / 2 * W), py = floor((1 - y/d) / 2 * H).
  double x = (2.0 * (px + 0.5) / side - 1.0) * depth;
  double y = (1.0 - 2.0 * (py + 0.5) / side) * depth;
  return {x, y, -depth};
}

PointCloud cloudOf(const std::vector<Dot>& dots, uint32_t side = kSide) {
  std::vector<glm::dvec3> points;
  std::vector<uint32_t> colors;
  for (const Dot& d : dots) {
    points.push_back(onPixel(d.px, d.py, d.depth, side));
    colors.push_back(d.color);
  }
  return cloudFromPoints(points, colors, 1e-6);
}

struct Drawn {
  std::vector<uint32_t> image;
  std::vector<uint64_t> words; // with the resolve stage on, or for closest-point methods
  FrameStats stats;
};

Drawn draw(gpu::Context& context, const PointCloud& cloud, Method method, const PostSettings& post,
           DepthMode depth = DepthMode::Float, uint32_t side = kSide) {
  UploadOptions upload;
  upload.progress = false;
  upload.layout = methodInfo(method).layout;
  GpuScene scene(context, cloud, upload);
  Renderer renderer(context, side, side);
  RenderSettings settings;
  settings.method = method;
  settings.depth = depth;
  settings.background = kBackground;
  settings.post = post;
  settings.captureWords = post.enabled() || hasCanonicalWords(methodInfo(method));
  Drawn d;
  d.stats = renderer.render(scene, axisCamera(), settings);
  d.image = renderer.image();
  if (settings.captureWords) d.words = renderer.framebufferWords();
  return d;
}

// Random dots on distinct depths (no two within 0.01 %, so float rounding never swaps two), unique colors;
// every fifth dot gets a second one on its pixel 30 % farther away, hidden at one pixel.
std::vector<Dot> randomDots(uint64_t seed, int count, double nearest, double farthest,
                            bool (*acceptDepth)(double) = nullptr) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pixel(0, kSide - 1);
  std::uniform_real_distribution<double> depth(nearest, farthest);
  std::vector<Dot> dots;
  std::vector<double> used;
  auto fresh = [&](double d) {
    if (acceptDepth && !acceptDepth(d)) return false;
    for (double u : used)
      if (std::abs(u - d) < 1e-4 * d) return false;
    return true;
  };
  while (int(dots.size()) < count) {
    double d = depth(rng);
    if (!fresh(d) || !fresh(d * 1.3)) continue;
    Dot dot{pixel(rng), pixel(rng), d, 0xFF000000u | uint32_t(dots.size() * 2654435761u & 0xFFFFFF)};
    used.push_back(d);
    dots.push_back(dot);
    if (dots.size() % 5 == 0) {
      used.push_back(d * 1.3);
      dots.push_back({dot.px, dot.py, d * 1.3, dot.color ^ 0x00FFFFFFu});
    }
  }
  return dots;
}

// CPU rasterization of each dot as a shape of size sizeOf(dot) anchored at its pixel, closest depth wins
// (the shape definitions of shaders/shared.h, written again here).
std::vector<uint32_t> cpuShapes(const std::vector<Dot>& dots, PointShape shape,
                                double (*sizeOf)(const Dot&)) {
  std::vector<double> depth(kSide * kSide, INFINITY);
  std::vector<uint32_t> image(kSide * kSide, kBackground);
  for (const Dot& dot : dots) {
    double s = sizeOf(dot);
    int n = int(std::lround(s));
    int lo = shape == PointShape::Square ? -((n - 1) / 2) : -int(s);
    int hi = shape == PointShape::Square ? n / 2 : int(s);
    for (int dy = lo; dy <= hi; ++dy) {
      for (int dx = lo; dx <= hi; ++dx) {
        if (shape == PointShape::Disc && dx * dx + dy * dy > 0.25 * s * s) continue;
        int x = dot.px + dx, y = dot.py + dy;
        if (x < 0 || y < 0 || x >= int(kSide) || y >= int(kSide)) continue;
        size_t i = size_t(y) * kSide + size_t(x);
        if (dot.depth < depth[i]) {
          depth[i] = dot.depth;
          image[i] = dot.color;
        }
      }
    }
  }
  return image;
}

// Pixels that differ, with the first few described.
::testing::AssertionResult sameImage(const std::vector<uint32_t>& gpu, const std::vector<uint32_t>& cpu,
                                     uint32_t side = kSide) {
  size_t differ = 0;
  std::string first;
  for (size_t i = 0; i < gpu.size(); ++i) {
    if (gpu[i] == cpu[i]) continue;
    if (++differ <= 4) {
      char text[96];
      std::snprintf(text, sizeof text, " (%zu,%zu): gpu %08x cpu %08x;", i % side, i / side, gpu[i], cpu[i]);
      first += text;
    }
  }
  if (differ == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << differ << " pixels differ:" << first;
}

const Method kMethods[] = {pointMethod("atomicmin"), pointMethod("batch"), pointMethod("hqs")};

float gSize = 0; // the size the sizeOf functions below read (they are plain function pointers)
double fixedSize(const Dot&) {
  return gSize;
}
// Attenuated: gSize pixels at depth 1 (axisCamera's target is 1 away), clamped to [1, 10].
double attenuatedSize(const Dot& dot) {
  return std::clamp(gSize / dot.depth, 1.0, 10.0);
}
// Depths whose attenuated size (for gSize = 12) is not within 1 % of a rounding edge of either shape: a
// square's side rounds at .5, a disc's r^2 = s^2 / 4 is compared with integers.
bool clearOfEdges(double depth) {
  double s = 12.0 / depth;
  double r2 = 0.25 * s * s;
  return std::abs(s - std::floor(s) - 0.5) > 0.01 && std::abs(r2 - std::round(r2)) > 0.01;
}

} // namespace

TEST(PostShaders, PushConstantsAndTilesMatchTheSharedStructs) {
  for (const char* name : {"post_splat.comp", "post_dilate.comp", "post_compose.comp"}) {
    gpu::SpirvReflection r = gpu::reflectSpirv(gpu::findShader(name));
    EXPECT_EQ(r.pushConstantSize, sizeof(shared::PostPush)) << name;
    EXPECT_EQ(r.localSize[0], shared::kPostTile) << name;
    EXPECT_EQ(r.localSize[1], shared::kPostTile) << name;
  }
  EXPECT_EQ(gpu::reflectSpirv(gpu::findShader("resolve_hqs.comp")).pushConstantSize,
            sizeof(shared::ResolvePush));
}

TEST_F(GpuTest, FixedPointSizeEqualsRasterizingShapesWithADepthTest) {
  std::vector<Dot> dots = randomDots(3, 150, 1.0, 6.0);
  PointCloud cloud = cloudOf(dots);
  for (PointShape shape : {PointShape::Square, PointShape::Disc}) {
    for (float size : {2.0f, 3.0f, 4.5f, 8.0f}) {
      gSize = size;
      std::vector<uint32_t> expected = cpuShapes(dots, shape, fixedSize);
      PostSettings post;
      post.pointSize = size;
      post.shape = shape;
      for (Method method : kMethods) {
        Drawn d = draw(*context, cloud, method, post);
        EXPECT_TRUE(sameImage(d.image, expected))
            << methodName(method) << ", " << pointShapeName(shape) << " of " << size << " px";
      }
      Drawn int40 = draw(*context, cloud, pointMethod("atomicmin"), post, DepthMode::Int40);
      EXPECT_TRUE(sameImage(int40.image, expected)) << "int40, " << pointShapeName(shape) << " of " << size;
    }
  }
}

TEST_F(GpuTest, AttenuatedPointSizeEqualsRasterizingShapesWithADepthTest) {
  // Sizes 12 / depth: 2 .. 12 pixels, clamped to 10; hidden dots 30 % farther are smaller.
  std::vector<Dot> dots = randomDots(4, 60, 1.0, 6.0, clearOfEdges);
  PointCloud cloud = cloudOf(dots);
  gSize = 12;
  for (PointShape shape : {PointShape::Square, PointShape::Disc}) {
    std::vector<uint32_t> expected = cpuShapes(dots, shape, attenuatedSize);
    PostSettings post;
    post.pointSize = 12;
    post.maxPointSize = 10;
    post.shape = shape;
    post.sizeMode = PointSizeMode::Attenuated;
    for (Method method : kMethods) {
      Drawn d = draw(*context, cloud, method, post);
      EXPECT_TRUE(sameImage(d.image, expected)) << methodName(method) << ", " << pointShapeName(shape);
    }
  }
}

TEST_F(GpuTest, PointSizeWordsKeepTheWinnersDepth) {
  // The words after the splat pass are words the 1-pixel frame had, moved: each is the word of some pixel
  // within reach, never a new one.
  std::vector<Dot> dots = randomDots(5, 120, 1.0, 6.0);
  PointCloud cloud = cloudOf(dots);
  Drawn one = draw(*context, cloud, pointMethod("atomicmin"), {});
  std::set<uint64_t> present(one.words.begin(), one.words.end());
  PostSettings post;
  post.pointSize = 5;
  Drawn five = draw(*context, cloud, pointMethod("atomicmin"), post);
  size_t lit = 0;
  for (size_t i = 0; i < five.words.size(); ++i) {
    EXPECT_TRUE(present.count(five.words[i])) << "pixel " << i;
    EXPECT_LE(five.words[i], one.words[i]) << "pixel " << i; // a pixel's own point, or a closer one
    lit += five.words[i] != shared::kEmptyPixel;
  }
  EXPECT_GT(lit, 1000u);
}

namespace {

// A flat surface facing the camera on pixels [x0, x1) x [y0, y1) at `depth`, minus the pixels in `holes`.
void addSurface(std::vector<Dot>& dots, int x0, int x1, int y0, int y1, double depth,
                const std::set<std::pair<int, int>>& holes = {}) {
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      if (!holes.count({x, y}))
        dots.push_back(
            {x, y, depth,
             0xFF000000u | uint32_t((x * 5 + y * 3 + int(depth * 7)) & 0xFF) << 8 | uint32_t(x * 4 & 0xFF)});
}

float depthOf(uint64_t word) {
  return std::bit_cast<float>(uint32_t(word >> 32));
}

// The dilation rule of post_dilate.comp, written again another way: a pixel is a hole when the
// directions to its closer (by more than 1 %) neighbours leave no gap of more than half a turn (no open
// half-plane through it holds them all); it takes the closest of them.
std::vector<uint64_t> cpuDilate(const std::vector<uint64_t>& words, int r, int side = int(kSide)) {
  std::vector<uint64_t> out(words.size());
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      uint64_t own = words[size_t(y * side + x)];
      double limit = own == shared::kEmptyPixel ? INFINITY : double(depthOf(own));
      uint64_t best = shared::kEmptyPixel;
      std::vector<double> angles;
      for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
          int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= side || qy >= side) continue;
          uint64_t w = words[size_t(qy * side + qx)];
          if (w == shared::kEmptyPixel || !(double(depthOf(w) * 1.01f) < limit))
            continue; // float, as the shader
          best = std::min(best, w);
          angles.push_back(std::atan2(double(dy), double(dx)));
        }
      }
      std::sort(angles.begin(), angles.end());
      double gap = angles.empty() ? 2 * M_PI : angles.front() + 2 * M_PI - angles.back();
      for (size_t k = 1; k < angles.size(); ++k)
        gap = std::max(gap, angles[k] - angles[k - 1]);
      out[size_t(y * side + x)] = gap < M_PI + 1e-9 ? best : own;
    }
  }
  return out;
}

} // namespace

TEST_F(GpuTest, DilationFillsAOnePixelHoleInAFlatSurface) {
  // A surface at depth 4 with an empty pixel at (20, 20), and a pixel at (30, 12) where a far point
  // (depth 40) shows through.
  std::vector<Dot> dots;
  addSurface(dots, 8, 40, 6, 40, 4.0, {{20, 20}, {30, 12}});
  dots.push_back({30, 12, 40.0, 0xFFFFFFFFu});
  PointCloud cloud = cloudOf(dots);
  PostSettings dilate;
  dilate.dilate = 1;
  for (Method method : {pointMethod("atomicmin"), pointMethod("batch")}) {
    Drawn before = draw(*context, cloud, method, {});
    Drawn after = draw(*context, cloud, method, dilate);
    for (auto [hx, hy] : {std::pair{20, 20}, std::pair{30, 12}}) {
      uint64_t closest = shared::kEmptyPixel;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (dx || dy) closest = std::min(closest, before.words[size_t((hy + dy) * int(kSide) + hx + dx)]);
      EXPECT_EQ(after.words[size_t(hy * int(kSide) + hx)], closest) << methodName(method) << " hole " << hx;
      EXPECT_EQ(depthOf(closest), depthOf(before.words[size_t(hy * int(kSide) + hx - 1)]));
    }
    size_t changed = 0;
    for (size_t i = 0; i < before.words.size(); ++i)
      changed += before.words[i] != after.words[i];
    EXPECT_EQ(changed, 2u) << methodName(method) << ": only the two holes change; the surface's edges stay";
  }
}

TEST_F(GpuTest, DilationNeverLetsAFarPointCoverANearOne) {
  // A far wall (depth 30) over the whole image; in front of it a near plate (depth 3) with a hole, a
  // single near point, and a thin near bar one pixel wide.
  std::vector<Dot> dots;
  addSurface(dots, 0, kSide, 0, kSide, 30.0);
  addSurface(dots, 10, 22, 10, 22, 3.0, {{15, 15}});
  dots.push_back({35, 8, 2.0, 0xFF0000FFu});
  addSurface(dots, 30, 31, 20, 40, 2.5);
  PointCloud cloud = cloudOf(dots);
  for (uint32_t r : {1u, 2u, 3u}) {
    PostSettings dilate;
    dilate.dilate = r;
    Drawn before = draw(*context, cloud, pointMethod("atomicmin"), {});
    Drawn after = draw(*context, cloud, pointMethod("atomicmin"), dilate);
    for (size_t i = 0; i < before.words.size(); ++i) {
      ASSERT_LE(depthOf(after.words[i]), depthOf(before.words[i])) << "pixel " << i << ", radius " << r;
      if (depthOf(before.words[i]) < 10) {
        ASSERT_EQ(after.words[i], before.words[i]) << "near pixel " << i;
      }
    }
    // The far wall keeps every pixel next to the plate's, the point's and the bar's silhouettes...
    for (int x = 0; x < int(kSide); ++x) {
      for (int y = 0; y < int(kSide); ++y) {
        size_t i = size_t(y * int(kSide) + x);
        bool insidePlate = x >= 10 && x < 22 && y >= 10 && y < 22;
        if (!insidePlate && depthOf(before.words[i]) > 10) {
          EXPECT_EQ(after.words[i], before.words[i]) << x << "," << y;
        }
      }
    }
    // ...and the plate's hole takes a plate point.
    EXPECT_EQ(depthOf(after.words[15 * kSide + 15]), depthOf(before.words[15 * kSide + 14]))
        << "radius " << r;
  }
}

TEST_F(GpuTest, DilationEqualsTheCpuRuleOnASparseScene) {
  std::vector<Dot> dots = randomDots(6, 700, 1.0, 3.0);
  PointCloud cloud = cloudOf(dots);
  for (Method method : {pointMethod("atomicmin"), pointMethod("batch-prefetch")}) {
    Drawn before = draw(*context, cloud, method, {});
    for (int r : {1, 2}) {
      PostSettings dilate;
      dilate.dilate = uint32_t(r);
      Drawn after = draw(*context, cloud, method, dilate);
      std::vector<uint64_t> expected = cpuDilate(before.words, r);
      size_t differ = 0, filled = 0;
      for (size_t i = 0; i < expected.size(); ++i) {
        differ += after.words[i] != expected[i];
        filled += before.words[i] != expected[i];
      }
      EXPECT_EQ(differ, 0u) << methodName(method) << ", radius " << r;
      EXPECT_GT(filled, 50u) << "the scene has holes to fill";
    }
  }
}

namespace {

// Eye-dome lighting as shared.h states Potree's formula, in double precision.
std::vector<uint32_t> cpuEdl(const std::vector<uint64_t>& words, double strength, double radius) {
  const int side = int(kSide);
  std::vector<uint32_t> image(words.size(), kBackground);
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      uint64_t w = words[size_t(y * side + x)];
      if (w == shared::kEmptyPixel) continue;
      double logDepth = std::log2(double(depthOf(w)));
      double sum = 0;
      for (int k = 0; k < 8; ++k) {
        double angle = k * 3.14159265358979323846 / 4;
        int qx = std::clamp(int(std::floor(x + 0.5 + radius * std::cos(angle))), 0, side - 1);
        int qy = std::clamp(int(std::floor(y + 0.5 + radius * std::sin(angle))), 0, side - 1);
        uint64_t n = words[size_t(qy * side + qx)];
        if (n != shared::kEmptyPixel) sum += std::max(0.0, logDepth - std::log2(double(depthOf(n))));
      }
      double shade = std::exp(-sum / 8 * 300.0 * strength);
      uint32_t color = 0xFF000000u;
      for (int c = 0; c < 3; ++c)
        color |= uint32_t(std::lround(double(uint32_t(w) >> (8 * c) & 0xFF) * shade)) << (8 * c);
      image[size_t(y * side + x)] = color;
    }
  }
  return image;
}

} // namespace

TEST_F(GpuTest, EyeDomeLightingMatchesACpuImplementationOfTheFormula) {
  // A bumpy surface (depths within 2 % of each other, so shades spread over 0..1) with holes, and a near
  // object whose silhouette darkens the surface next to it.
  std::vector<Dot> dots;
  std::mt19937_64 rng(8);
  for (int y = 0; y < int(kSide); ++y)
    for (int x = 0; x < int(kSide); ++x)
      if (rng() % 10 != 0)
        dots.push_back({x, y, 3.0 * (1 + 0.002 * double((x * 7 + y * 13) % 11)),
                        0xFF000000u | uint32_t(rng() & 0xFFFFFF)});
  addSurface(dots, 20, 30, 14, 24, 2.0);
  PointCloud cloud = cloudOf(dots);
  for (auto [strength, radius] : {std::pair{1.0f, 1.4f}, std::pair{0.4f, 3.0f}}) {
    PostSettings edl;
    edl.edlStrength = strength;
    edl.edlRadius = radius;
    std::vector<uint32_t> expected;
    Drawn plain;
    for (Method method : {pointMethod("atomicmin"), pointMethod("batch")}) {
      plain = draw(*context, cloud, method, {});
      expected = cpuEdl(plain.words, strength, radius);
      Drawn lit = draw(*context, cloud, method, edl);
      int worst = 0;
      for (size_t i = 0; i < expected.size(); ++i)
        for (int c = 0; c < 4; ++c)
          worst = std::max(
              worst, std::abs(int(lit.image[i] >> (8 * c) & 0xFF) - int(expected[i] >> (8 * c) & 0xFF)));
      EXPECT_LE(worst, 1) << methodName(method) << ", strength " << strength << ", radius " << radius;
      EXPECT_EQ(lit.words, plain.words) << "eye-dome lighting changes colors in the image only";
    }
    // The test means something: some pixels are darkened, some not.
    size_t darker = 0;
    for (size_t i = 0; i < expected.size(); ++i)
      darker +=
          expected[i] != (plain.words[i] == shared::kEmptyPixel ? kBackground : uint32_t(plain.words[i]));
    EXPECT_GT(darker, 300u);
    EXPECT_LT(darker, expected.size() - 300);
  }
}

namespace {

// Six points with every attribute set by hand, on pixels (4 + 6k, 10).
PointCloud attributeCloud() {
  std::vector<Dot> dots;
  for (int k = 0; k < 6; ++k)
    dots.push_back({4 + 6 * k, 10, 4.0, packRgba(uint32_t(40 * k), 100, 200)});
  PointCloud cloud = cloudOf(dots);
  cloud.source = "hand-built";
  cloud.intensity = {0, 100, 200, 300, 400, 400};
  cloud.classification = {2, 6, 9, 5, 7, 2};
  cloud.returnNumber = {1, 2, 3, 1, 4, 2};
  cloud.pointSourceId = {11, 12, 11, 13, 14, 11};
  return cloud;
}

// The colors on the six points' pixels.
std::vector<uint32_t> pixelsOf(const std::vector<uint32_t>& image) {
  std::vector<uint32_t> out;
  for (int k = 0; k < 6; ++k)
    out.push_back(image[size_t(10 * kSide + 4 + 6 * k)]);
  return out;
}

} // namespace

TEST_F(GpuTest, EachColorModeMapsAHandBuiltCloud) {
  using Source = DisplayColorMode::Source;
  PointCloud cloud = attributeCloud();
  std::map<Source, std::vector<uint32_t>> expected = {
      {Source::Rgb,
       {packRgba(0, 100, 200), packRgba(40, 100, 200), packRgba(80, 100, 200), packRgba(120, 100, 200),
        packRgba(160, 100, 200), packRgba(200, 100, 200)}},
      {Source::Intensity, // range 0..400: black, a quarter, half (127.5 rounds up), three quarters, white
       {packRgba(0, 0, 0), packRgba(64, 64, 64), packRgba(128, 128, 128), packRgba(191, 191, 191),
        packRgba(255, 255, 255), packRgba(255, 255, 255)}},
      {Source::Classification, // ground, building, water, high vegetation, low point (noise), ground
       {packRgba(166, 110, 60), packRgba(235, 140, 40), packRgba(40, 110, 230), packRgba(20, 110, 30),
        packRgba(255, 0, 255), packRgba(166, 110, 60)}},
      {Source::ReturnNumber,
       {packRgba(230, 50, 40), packRgba(40, 180, 60), packRgba(50, 90, 230), packRgba(230, 50, 40),
        packRgba(240, 200, 30), packRgba(40, 180, 60)}},
      {Source::PointSource,
       {pointSourceColor(11), pointSourceColor(12), pointSourceColor(11), pointSourceColor(13),
        pointSourceColor(14), pointSourceColor(11)}},
  };
  // Every point is at world z = -4: Turbo's ends and middle for ranges that put -4 at 0, 0.5 and 1.
  std::vector<std::pair<ColorRange, uint32_t>> elevation = {
      {{-4, 0}, packRgba(35, 23, 27)}, {{-5, -3}, packRgba(152, 250, 79)}, {{-8, -4}, packRgba(144, 13, 0)}};
  for (Method method : {pointMethod("atomicmin"), pointMethod("batch")}) {
    for (auto& [source, colors] : expected) {
      UploadOptions upload;
      upload.progress = false;
      upload.layout = methodInfo(method).layout;
      upload.colors = displayColorMode(cloud, source, ColorRange{0, 400});
      GpuScene scene(*context, cloud, upload);
      Renderer renderer(*context, kSide, kSide);
      RenderSettings settings;
      settings.method = method;
      renderer.render(scene, axisCamera(), settings);
      EXPECT_EQ(pixelsOf(renderer.image()), colors) << methodName(method) << ", " << colorSourceName(source);
    }
    for (auto [range, color] : elevation) {
      UploadOptions upload;
      upload.progress = false;
      upload.layout = methodInfo(method).layout;
      upload.colors = displayColorMode(cloud, Source::Elevation, range);
      GpuScene scene(*context, cloud, upload);
      Renderer renderer(*context, kSide, kSide);
      RenderSettings settings;
      settings.method = method;
      renderer.render(scene, axisCamera(), settings);
      EXPECT_EQ(pixelsOf(renderer.image()), std::vector<uint32_t>(6, color))
          << methodName(method) << ", elevation " << range.lo << ".." << range.hi;
    }
  }
}

TEST_F(GpuTest, RecoloringEqualsUploadingInTheMode) {
  using Source = DisplayColorMode::Source;
  PointCloud cloud = attributeCloud();
  for (Method method : {pointMethod("atomicmin"), pointMethod("batch")}) {
    UploadOptions upload;
    upload.progress = false;
    upload.layout = methodInfo(method).layout;
    upload.maxPartPoints = methodInfo(method).layout == SceneLayout::Batched ? 0 : 4; // two parts
    GpuScene recolored(*context, cloud, upload);
    Renderer renderer(*context, kSide, kSide);
    RenderSettings settings;
    settings.method = method;
    for (Source source : {Source::Classification, Source::PointSource, Source::Intensity}) {
      DisplayColorMode mode = displayColorMode(cloud, source);
      recolored.recolor(*context, cloud, mode);
      renderer.render(recolored, axisCamera(), settings);
      std::vector<uint32_t> afterRecolor = renderer.image();
      upload.colors = mode;
      GpuScene fresh(*context, cloud, upload);
      renderer.render(fresh, axisCamera(), settings);
      EXPECT_EQ(afterRecolor, renderer.image()) << methodName(method) << ", " << colorSourceName(source);
    }
  }
}

TEST_F(GpuTest, PostStageOnOneEyeOfAWiderBufferEqualsItAlone) {
  // Two different frames side by side in one buffer of 2W x H, as a stereo renderer keeps its eyes:
  // running the stage on each eye's window must give what it gives on each frame alone, with nothing
  // leaking across the seam (every pass of it reads neighbours).
  const uint32_t w = kSide, h = kSide;
  std::vector<uint64_t> eyes[2];
  for (int e = 0; e < 2; ++e)
    eyes[e] =
        draw(*context, cloudOf(randomDots(10 + uint64_t(e), 300, 1.0, 2.0)), pointMethod("atomicmin"), {})
            .words;
  PostSettings post;
  post.pointSize = 4;
  post.dilate = 2;
  post.edlStrength = 1;
  post.edlRadius = 2;
  auto buffer = [&](uint64_t bytes, gpu::MemoryKind kind) {
    return gpu::Buffer(*context, bytes, gpu::kBufferUsage, kind, "post test");
  };
  PostStage stage(*context);
  // Each eye alone.
  std::vector<uint32_t> alone[2];
  std::vector<uint64_t> aloneWords[2];
  for (int e = 0; e < 2; ++e) {
    gpu::Buffer words = buffer(uint64_t(w) * h * 8, gpu::MemoryKind::Upload);
    std::memcpy(words.mapped(), eyes[e].data(), eyes[e].size() * 8);
    gpu::Buffer image = buffer(uint64_t(w) * h * 4, gpu::MemoryKind::Readback);
    PostView view{words.address(), image.address(), w, h, w, 1.0f, kBackground, true};
    context->submitAndWait([&](VkCommandBuffer cmd) { stage.record(cmd, view, post); });
    image.invalidate();
    alone[e].assign(static_cast<uint32_t*>(image.mapped()), static_cast<uint32_t*>(image.mapped()) + w * h);
    aloneWords[e].assign(static_cast<uint64_t*>(words.mapped()),
                         static_cast<uint64_t*>(words.mapped()) + w * h);
  }
  // Both eyes in one buffer.
  gpu::Buffer words = buffer(uint64_t(2 * w) * h * 8, gpu::MemoryKind::Upload);
  auto* wide = static_cast<uint64_t*>(words.mapped());
  for (uint32_t y = 0; y < h; ++y)
    for (int e = 0; e < 2; ++e)
      std::memcpy(wide + y * 2 * w + uint32_t(e) * w, eyes[e].data() + y * w, w * 8);
  gpu::Buffer image = buffer(uint64_t(2 * w) * h * 4, gpu::MemoryKind::Readback);
  context->submitAndWait([&](VkCommandBuffer cmd) {
    for (uint32_t e = 0; e < 2; ++e) {
      PostView view{
          words.address() + e * w * 8, image.address() + e * w * 4, w, h, 2 * w, 1.0f, kBackground, true};
      stage.record(cmd, view, post);
    }
  });
  image.invalidate();
  const auto* pixels = static_cast<const uint32_t*>(image.mapped());
  for (int e = 0; e < 2; ++e) {
    std::vector<uint32_t> eyeImage;
    std::vector<uint64_t> eyeWords;
    for (uint32_t y = 0; y < h; ++y) {
      eyeImage.insert(eyeImage.end(), pixels + y * 2 * w + uint32_t(e) * w,
                      pixels + y * 2 * w + uint32_t(e) * w + w);
      eyeWords.insert(eyeWords.end(), wide + y * 2 * w + uint32_t(e) * w,
                      wide + y * 2 * w + uint32_t(e) * w + w);
    }
    EXPECT_EQ(eyeImage, alone[e]) << "eye " << e;
    EXPECT_EQ(eyeWords, aloneWords[e]) << "eye " << e;
  }
  EXPECT_NE(alone[0], alone[1]);
}

TEST_F(GpuTest, PostSettingsOutOfRangeAndHwPointsAreClearErrors) {
  PointCloud cloud = cloudOf(randomDots(12, 20, 1.0, 2.0));
  UploadOptions upload;
  upload.progress = false;
  GpuScene scene(*context, cloud, upload);
  Renderer renderer(*context, kSide, kSide);
  auto refused = [&](PostSettings post, Method method, const char* words) {
    RenderSettings settings;
    settings.method = method;
    settings.post = post;
    try {
      renderer.render(scene, axisCamera(), settings);
      return ::testing::AssertionFailure() << "no error";
    } catch (const InputError& e) {
      if (std::string(e.what()).find(words) == std::string::npos)
        return ::testing::AssertionFailure() << e.what();
      return ::testing::AssertionSuccess();
    }
  };
  PostSettings big;
  big.pointSize = 33;
  EXPECT_TRUE(refused(big, pointMethod("atomicmin"), "1..32"));
  PostSettings adaptive;
  adaptive.sizeMode = PointSizeMode::Adaptive;
  EXPECT_TRUE(refused(adaptive, pointMethod("atomicmin"), "LOD"));
  PostSettings wide;
  wide.dilate = 9;
  EXPECT_TRUE(refused(wide, pointMethod("atomicmin"), "0..8"));
  PostSettings edl;
  edl.edlStrength = 1;
  EXPECT_TRUE(refused(edl, pointMethod("hw-points"), "hw-points"));
  edl.edlRadius = 0;
  EXPECT_TRUE(refused(edl, pointMethod("atomicmin"), "radius"));
}

TEST_F(GpuTest, PostPassesAreTimed) {
  PointCloud cloud = cloudOf(randomDots(13, 200, 1.0, 2.0));
  PostSettings post;
  post.pointSize = 3;
  post.edlStrength = 1;
  Drawn d = draw(*context, cloud, pointMethod("atomicmin"), post);
  ASSERT_TRUE(d.stats.post);
  EXPECT_GT(d.stats.post->splatMs, 0.0);
  EXPECT_GE(d.stats.post->dilateMs, 0.0);
  EXPECT_GT(d.stats.post->composeMs, 0.0);
  EXPECT_GE(d.stats.medianMs, d.stats.post->splatMs);
  Drawn plain = draw(*context, cloud, pointMethod("atomicmin"), {});
  EXPECT_FALSE(plain.stats.post);
}

} // namespace pointrast::test

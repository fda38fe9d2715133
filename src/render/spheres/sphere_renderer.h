// Draws a particle set as ray-cast spheres with one of the sphere methods and returns an RGBA8 image,
// plus the per-pixel view depth and particle index for tests. Every method shades with
// shaders/sphere_shade.inc.glsl and is checked against the tests' CPU ray caster (tests/oracles/).
//
// Methods, after Gralka et al., "Efficient Sphere Rendering Revisited" (2023): the study draws ray-cast
// sphere impostors through every rasterization pipeline (points, triangles, strips, geometry and mesh
// shaders) and ray tracing; pointrast adds sphere-compute, the software rasterizer of the point methods
// applied to spheres. A new method is one enum value, one row of the table and one implementation.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "render/camera.h"
#include "render/spheres/gpu_particles.h"

namespace pointrast {

namespace gpu {
class Context;
}

enum class SphereMethod {
  Compute,   // compute rasterization into a 64-bit visibility buffer, large spheres in chunks, then a resolve
  Points,    // hardware point list, gl_PointSize from the projected bounds
  Triangles, // hardware triangle list, 6 vertices per sphere
  Strip,     // hardware triangle strips, one instance of 4 vertices per sphere
  Geometry,  // hardware points expanded into strips by a geometry shader
  MeshPoints,    // VK_EXT_mesh_shader: a meshlet of spheres per workgroup, one point each
  MeshTriangles, // VK_EXT_mesh_shader: a meshlet of spheres per workgroup, one quad (2 triangles) each
  RayTracing,    // VK_KHR_ray_tracing_pipeline: one AABB per sphere, an intersection shader, a ray per pixel
};

struct SphereSettings;

struct SphereMethodInfo {
  SphereMethod method;
  const char* name;
  const char* description;
  // Whether the device can run the method; why: one sentence when it cannot.
  bool (*supported)(gpu::Context& context, std::string* why);
  // Methods that rasterize billboards: whether the device can draw them with the settings' billboard and
  // conservative rasterization (why: one sentence when it cannot). nullptr: the method draws no
  // billboards, and takes only the default settings (screen, not conservative).
  bool (*rasterOptions)(gpu::Context& context, const SphereSettings& settings, std::string* why) = nullptr;
};
std::span<const SphereMethodInfo> sphereMethodTable();
const SphereMethodInfo& sphereMethodInfo(SphereMethod method);
// Throws InputError listing the known names.
SphereMethod parseSphereMethod(std::string_view name);
bool isSphereMethodName(std::string_view name);
const char* sphereMethodName(SphereMethod method);
// Whether the method rasterizes billboards, so that --billboard and --conservative apply to it.
bool sphereMethodTakesBillboards(SphereMethod method);
// "sphere-points, sphere-triangles, ...": the methods that do, for messages and help.
std::string billboardMethodNames();

// The impostor each sphere is rasterized as (shaders/sphere_impostor.inc.glsl):
enum class SphereBillboard {
  Screen, // the tight screen-space box of the sphere's projection (an ellipse), plus a quarter pixel
  Camera, // a square parallel to the image plane through the center, side 2r enlarged to cover the
          // sphere's perspective projection; looser than the box, cheaper to set up
};
// Throws InputError naming the choices.
SphereBillboard parseSphereBillboard(std::string_view name);
const char* sphereBillboardName(SphereBillboard billboard);

struct SphereSettings {
  SphereMethod method = SphereMethod::Compute;
  uint32_t background = 0xFF000000u; // RGBA8
  uint32_t frames = 1;               // timed frames; the median is reported
  uint32_t warmup = 1;               // untimed frames first
  // sphere-compute: entries of the large-sphere chunk list; 0 = the default (8 M chunks, 128 MiB). Tests
  // set a small one to exercise the overflow path (spheres drawn by their own thread).
  uint32_t chunkCapacity = 0;
  // sphere-compute: skip large-sphere chunks behind their tile's depth bound (off only to compare the
  // work), and count the work (pixels tested, depth atomics, skipped chunks: one global atomic each,
  // so the frame is slower; for tests and measurements of the work, not for timing).
  bool tileBound = true;
  bool countWork = false;
  // sphere-compute: occlusion culling of batches of 128 consecutive particles (draw last frame's visible
  // batches, test the others against the depth they left, draw those that may show). The image is the
  // same with it off; off only to compare.
  bool occlusionCull = true;
  // sphere-compute: large spheres whose box has more pixels than this are cut along screen tiles, smaller
  // ones into bands of box rows; 0 = the default (shared::kSphereTileCutPixels). Only to count the work
  // of other choices; the image is the same for every value.
  uint32_t tileCutPixels = 0;
  // Methods that rasterize billboards (sphereMethodTakesBillboards): the impostor, and overestimating
  // conservative rasterization (VK_EXT_conservative_rasterization). Others refuse anything but the default.
  SphereBillboard billboard = SphereBillboard::Screen;
  bool conservative = false;
  // sphere-mesh-*: spheres per mesh workgroup, kSphereMeshletLarge (31) or kSphereMeshletSmall (15)
  // (render() throws InputError for others), and a task shader that culls spheres before the mesh stage.
  uint32_t meshlet = 31;
  bool taskCull = false;
  // sphere-rt: particles per bottom-level structure; 0 = a whole part while the build's scratch fits the
  // device's largest buffer, else halved until it does. Tests set a small one to exercise the pieces.
  uint32_t rtPieceParticles = 0;
};

struct SphereStats {
  double medianMs = 0, minMs = 0, maxMs = 0; // GPU time of clear + draw + resolve, timestamp queries
  uint32_t frames = 0;
  uint64_t particles = 0;      // particles submitted per frame
  uint64_t largeChunks = 0;    // sphere-compute: chunks (tiles, bands) of large spheres listed, last frame
  // sphere-compute with occlusion culling, the last frame: batches of the set, batches that may show (the
  // next frame's first draw), and batches its second draw took (not drawn first, found to show)
  uint64_t batches = 0, visibleBatches = 0, lateBatches = 0;
  uint64_t spilledSpheres = 0; // sphere-compute: large spheres that drew chunks themselves (list full)
  // sphere-compute with SphereSettings::countWork, the last frame: pixels tested (each one read of the
  // visibility word, then the ray test unless early-z rejects it), of which in large-sphere chunks,
  // 64-bit depth atomics, and large-sphere chunks skipped by their tile's depth bound.
  uint64_t pixelsTested = 0, largePixelsTested = 0, depthAtomics = 0, skippedChunks = 0;
  uint64_t clampedSpheres = 0; // sphere-points, sphere-mesh-points: spheres larger than the largest point,
                               // drawn incomplete
  // GPU time of what a method builds from the particles before the frames, timestamp queries; not part of
  // the frame times above. sphere-rt: the acceleration structures (AABBs, bottom and top levels), every
  // render; sphere-compute: the batches' bounds, once per upload (0 after).
  double buildMs = 0;
  uint64_t rtBottomLevels = 0; // sphere-rt: bottom-level structures built (a piece of a part each)
};

class SphereMethodImpl;
struct SphereTargets;

class SphereRenderer {
public:
  // Throws InputError for a zero or oversized image.
  SphereRenderer(gpu::Context& context, uint32_t width, uint32_t height);
  ~SphereRenderer();

  // Throws UnsupportedError if the device cannot run the method, InputError for a bad camera.
  SphereStats render(const GpuParticles& particles, const Camera& camera, const SphereSettings& settings);

  // RGBA8 pixels of the last frame, row 0 at the top.
  std::vector<uint32_t> image();
  // Linear view depth of the visible sphere per pixel of the last frame, +infinity where none.
  std::vector<float> depth();
  // Particle index of the visible sphere per pixel of the last frame, kNoParticle where none.
  std::vector<uint32_t> indices();

  uint32_t width() const;
  uint32_t height() const;

  static bool supports(gpu::Context& context, SphereMethod method, std::string* why = nullptr);
  // The method with the settings' billboard and conservative rasterization. Throws InputError when the
  // method takes no such settings (sphere-compute draws no billboards); false with why when the device
  // cannot (conservative rasterization missing).
  static bool supports(gpu::Context& context, const SphereSettings& settings, std::string* why = nullptr);

private:
  SphereMethodImpl& method(SphereMethod method);
  gpu::Context& context_;
  std::unique_ptr<SphereTargets> targets_;
  std::vector<std::pair<SphereMethod, std::unique_ptr<SphereMethodImpl>>> methods_;
  SphereMethodImpl* last_ = nullptr; // the method of the last frame (depth and indices come from it)
  std::shared_ptr<const std::vector<uint32_t>> lastOrder_; // GpuParticles::order() of the last frame
};

} // namespace pointrast

// What the commands take as input: a file, or the name of a generated scene; points for the point
// renderers, particles (spheres) for the sphere renderers.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "cloud/cloud.h"
#include "cloud/order.h"
#include "cloud/particles.h"
#include "render/camera.h"
#include "view/scene_source.h"

namespace pointrast::app {

struct InputSpec {
  std::string source;          // a path, or a scene name ("terrain", "tls"); empty = demo scene
  uint64_t points = 1'000'000; // for scenes
  uint64_t seed = 1;           // for scenes and shuffled orders
  Order order = Order::Original;
  bool progress = true;
  bool classification = false; // a generated scene's ASPRS classes too (files have what they have)
};

// The input of the commands that take a point cloud (render, view, serve) from their shared options: FILE or
// a scene name, --points, --seed, --order; progress unless quiet. Throws InputError naming a bad option.
InputSpec inputSpec(const std::string& source, const std::string& points, uint64_t seed,
                    const std::string& order, bool quiet);

// --eye, --target and --up with --fov as the starting camera of a viewer (--target defaults to `center`);
// nullopt without --eye. Throws InputError for a bad vector or a camera that cannot look.
std::optional<Camera> cameraFromOptions(const std::string& eye, const std::string& target,
                                        const std::string& up, double fov, const glm::dvec3& center);

// The built-in demo: the terrain scene, 1 M points, seed 1.
constexpr const char* kDemoScene = "terrain";
constexpr uint64_t kDemoPoints = 1'000'000;

// Whether something exists at `path`: false when nothing does (the name may be a scene's), InputError
// naming the path when the question has no answer (a symbolic link loop, a name too long, a folder that
// may not be searched).
bool pathExists(const std::string& path);

// What the viewers open: an octree (a folder or file the format table serves nodes from: our octrees,
// Potree 2.0, COPC, EPT) as a node source streamed by the LOD methods, anything else read as loadInput
// does. A method, when named, decides for a file that is both (COPC is also a LAZ file): a LOD method
// streams it, any other reads it whole. Throws InputError as loadInput, for a LOD method named for an input
// that is no octree, and for --order with an octree (whose nodes keep their order).
//
// A cloud file that does not fit `gpuBudget` bytes (when given; 16 bytes a point uploaded), or that a LOD
// method was named for, is not refused: its octree is built once into the octree cache (`octreeCache`,
// the one `bench` uses; keyed by the file's path, size and modification time) with progress lines, and
// then streamed; a later open reuses it. `onNote` receives the cache's lines (a build, a damaged entry).
struct SceneOptions {
  std::optional<Method> method;
  uint64_t gpuBudget = 0; // 0: no limit checked here
  std::filesystem::path octreeCache; // empty: bench::defaultOctreeCacheDir()
  std::function<void(const std::string&)> onNote;
};
view::SceneInput openScene(const InputSpec& spec, const SceneOptions& options = {});
// A rank's part of the input under mpirun (docs/mpi.md): an octree opened whole (each frame draws the
// rank's share of its selection), a cloud's share (loadShare) with the whole input's bounds and point
// count. Refuses an input openScene would build an octree of. A collective.
view::SceneInput openSceneShare(const InputSpec& spec, const SceneOptions& options = {});
// The refusals of openScene that need no reading, said before a device starts or a file is read.
void checkSceneMethod(const InputSpec& spec, std::optional<Method> method);
// The octree cache's key of a file: its name and a hash of its absolute path, size and modification time.
std::string fileOctreeKey(const std::filesystem::path& file);

// Reads the file or generates the scene, then applies the order. Throws InputError for a source that is
// neither an existing file nor a scene name.
PointCloud loadInput(const InputSpec& spec);
// The points loadInput will return, known without reading them: a file's header count, a scene's size;
// nullopt where only reading tells (XYZ text) or loadInput will refuse the source. Throws InputError for
// an unreadable file, as loadInput would.
std::optional<uint64_t> statedPoints(const InputSpec& spec);

struct ParticleInputSpec {
  // An MMPLD file; a point cloud file or a point scene name (terrain, tls), drawn as spheres of `radius`;
  // or a particle scene name (particles-block, ...). Empty = the particle demo scene.
  std::string source;
  uint32_t frame = 0; // MMPLD: the frame to read
  // Points: the spheres' radius, required. Particle scenes: 0 = the scene default (0.5). MMPLD: 0 = the
  // file's radii, anything else replaces them.
  float radius = 0;
  bool perParticleRadius = false; // particle scenes: radii vary per particle around `radius`
  uint64_t particles = 1'000'000; // scenes
  uint64_t seed = 1;              // scenes
  bool progress = true;
};

// The built-in particle demo: particles-block, 1 M particles, seed 1.
constexpr const char* kDemoParticleScene = "particles-block";

// Reads or generates the particles (for the sphere renderers). Throws InputError for a source that is
// neither an existing file nor a scene name, a point input without a radius, or a negative radius.
ParticleSet loadParticles(const ParticleInputSpec& spec);
// The particles loadParticles will return, as statedPoints() does for points (MMPLD: the frame's lists).
std::optional<uint64_t> statedParticles(const ParticleInputSpec& spec);

} // namespace pointrast::app

// What a viewer draws, whatever was opened: the one interface between a front end and its input on the GPU.
//
//   SceneInput   (host)  a cloud read into memory, or an octree's node source (our octrees, Potree 2.0
//                        folders, COPC, EPT): what app/ opens from a file, a generated scene or a folder.
//   SceneSource  (GPU)   draws one interactive frame of that input with a Renderer:
//                          GpuCloud  - the cloud uploaded whole, in the layouts its methods read
//                                      (scene_view.h), drawn by the brute-force and batch methods;
//                          GpuOctree - the octree streamed through the node cache (render/lod/lod_scene.h),
//                                      drawn by the LOD methods; a frame draws what is resident and never
//                                      waits for the disk, and changed() says more nodes are coming.
//
// A front end (the desktop viewer, the browser viewer's clients) holds a SceneSource and one SceneView per
// image; it never asks which kind it holds: draws() lists the methods it offers, defaultMethod() the one
// it starts with, changed() when to draw again without input.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cloud/cloud.h"
#include "render/renderer.h"
#include "view/session.h"

namespace pointrast {
namespace gpu {
class Context;
}
namespace lod {
class NodeSource;
class LodScene;
} // namespace lod
} // namespace pointrast

namespace pointrast::view {

// An input opened on the host, before any device: exactly one of cloud and octree.
struct SceneInput {
  std::unique_ptr<PointCloud> cloud;
  std::unique_ptr<lod::NodeSource> octree;
  std::string name;     // the file or scene, for titles and messages
  Bounds bounds;        // the points' bounds (an octree's cube when it states none)
  uint64_t points = 0;  // points of the cloud, or of the whole octree
  std::vector<glm::dvec3> framing; // points the overview frames (render/camera.h framingSample)
  SceneInput();
  SceneInput(SceneInput&&) noexcept;
  SceneInput& operator=(SceneInput&&) noexcept;
  ~SceneInput();
  static SceneInput fromCloud(PointCloud cloud);
  // Takes the metadata's bounds and count. Throws InputError for a source whose metadata has no extent.
  static SceneInput fromOctree(std::unique_ptr<lod::NodeSource> source);
};

class SceneSource {
public:
  virtual ~SceneSource() = default;
  virtual const std::string& name() const = 0;
  virtual const Bounds& bounds() const = 0;
  virtual uint64_t pointCount() const = 0;
  // Whether this source is drawn by the LOD methods (SceneLayout::Octree) rather than those reading an
  // uploaded cloud.
  virtual bool streamed() const = 0;
  bool draws(Method method) const { return (methodInfo(method).layout == SceneLayout::Octree) == streamed(); }
  // Bytes of GPU memory the source occupies (uploaded layouts, or the node cache's resident pages).
  virtual uint64_t bytes() const = 0;
  // One interactive frame with the settings' method (one the source draws) into `renderer`. The view
  // settings carry what the source itself applies (colors; the node cache's budget). A setting it cannot
  // apply, or a damaged node met while streaming, leaves the frame as it can be drawn and says why in
  // `status`; nothing here throws for bad data. A frame not drawn at all returns FrameStats::frames 0.
  virtual FrameStats draw(Renderer& renderer, const Camera& camera, const RenderSettings& rs,
                          const ViewSettings& settings, std::string& status) = 0;
  // Whether a frame drawn now would differ from the last one without any input: nodes still arriving.
  virtual bool changed() const { return false; }
  // Why the points a frame shows cannot be read on this host (a rank of a distributed viewer holds only
  // its share of them), for the tools that read them (the pick tool and its measurements); empty when they
  // can.
  virtual std::string pointsElsewhere() const { return {}; }
  // Why this source does not draw a method it would draw by its layout (a distributed viewer's frames must
  // composite), or nothing. methodsFor() leaves such methods out.
  virtual std::optional<std::string> refuses(Method) const { return std::nullopt; }
};

// The part of an input one process draws: share `index` of `count` (docs/mpi.md); {0, 1} is the whole.
struct DrawShare {
  uint32_t index = 0, count = 1;
};

// The method a viewer starts with on this device: lod for an octree; for a cloud the fastest the device
// runs (batch-prefetch on a discrete GPU, atomicmin on others, where the batch methods' work per point
// does not pay).
Method defaultMethod(const SceneSource& source, const gpu::Context& context);
// "--method X does not draw FILE, an octree: its methods are lod, lod-hqs": for a method the source does
// not draw.
std::string notDrawn(const SceneSource& source, Method method);
// The methods of the source this device runs, in table order.
std::vector<Method> methodsFor(const SceneSource& source, const gpu::Context& context);

// The octree counterpart of GpuCloud: a LodScene over the input's node source, made again when the
// settings' colors or node cache budget change.
class GpuOctree : public SceneSource {
public:
  // The node source must outlive this. Throws InputError for a source whose root is unusable,
  // UnsupportedError when the budget holds no page.
  GpuOctree(gpu::Context& context, lod::NodeSource& source, const std::string& name, const Bounds& bounds,
            uint64_t points, const ViewSettings& settings = {}, DrawShare share = {});
  ~GpuOctree() override;
  const std::string& name() const override { return name_; }
  const Bounds& bounds() const override { return bounds_; }
  uint64_t pointCount() const override { return points_; }
  bool streamed() const override { return true; }
  uint64_t bytes() const override;
  FrameStats draw(Renderer& renderer, const Camera& camera, const RenderSettings& rs,
                  const ViewSettings& settings, std::string& status) override;
  bool changed() const override { return scene_ && !converged_ && !failed_; }
  lod::LodScene& scene() { return *scene_; }

private:
  struct Options {
    std::optional<DisplayColorMode::Source> colorSource;
    std::optional<ColorRange> colorRange;
    uint64_t gpuBytes = 0;
    bool operator==(const Options& other) const;
  };
  static Options optionsOf(const ViewSettings& settings);
  void make(const Options& options);

  gpu::Context& context_;
  lod::NodeSource& source_;
  std::string name_;
  Bounds bounds_;
  uint64_t points_;
  DrawShare share_;
  Options options_;
  std::unique_ptr<lod::LodScene> scene_;
  std::string error_; // why the last change of options was refused, said with every frame until the next
  bool converged_ = false;
  bool failed_ = false; // the last frame met a damaged node: draw again on input only
};

// The GPU side of an opened input: a GpuOctree for an octree, a GpuCloud for a cloud (uploaded on first
// use, with progress lines unless quiet). An octree's frames draw `share` of each selection; a cloud is
// already only its share.
std::unique_ptr<SceneSource> makeSceneSource(gpu::Context& context, SceneInput& input,
                                             const ViewSettings& settings, bool progress,
                                             DrawShare share = {});

} // namespace pointrast::view

// The GPU side of an interactive session, shared by the front ends: the input on the GPU (a SceneSource,
// scene_source.h: GpuCloud below for a cloud uploaded in the layouts its methods read, each on first use, or
// a GpuOctree streamed through the node cache), and per view one Renderer at the viewport's size, picking
// the point under a pixel from the framebuffer words, and screenshots (optionally supersampled). Views of
// one source share it: the browser viewer's clients each have a SceneView (their own camera and image
// size) drawing one source. Like the rest of the gpu layer, one thread at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "cloud/annotations.h"
#include "render/renderer.h"
#include "view/navigation.h"
#include "view/scene_source.h"
#include "view/session.h"

namespace pointrast {
struct PointCloud;
namespace gpu {
class Context;
}
} // namespace pointrast

namespace pointrast::view {

// The renderer's settings for one interactive frame: one timed frame, no warm-up.
RenderSettings renderSettings(const ViewSettings& settings);

// Pixels within this distance of a picked position are searched for the closest point, so that a
// double-click between the points of a sparse cloud still finds one.
constexpr uint32_t kPickRadius = 2;

// The RGBA8 image of width x height pixels reduced by `factor` per side: each output pixel is the
// rounded mean of its factor x factor block, per channel. width and height are multiples of factor.
std::vector<uint32_t> boxDownsample(std::span<const uint32_t> rgba, uint32_t width, uint32_t height,
                                    uint32_t factor);

class GpuCloud : public SceneSource {
public:
  // Keeps a reference to the cloud (it must outlive this) to upload a layout when a method first needs
  // it. Uploads throw UnsupportedError when the device lacks the memory.
  GpuCloud(gpu::Context& context, const PointCloud& cloud, bool progress = true);
  ~GpuCloud() override;
  const GpuScene& scene(SceneLayout layout);
  // Colors the uploaded layouts, and those uploaded later, as render --color and --color-range would (no
  // source: the automatic choice). Rewrites only the colors, and only when the choice changed. Returns
  // the sentence why not when the cloud lacks the attribute; the colors then stay as they were.
  std::optional<std::string> setColors(std::optional<DisplayColorMode::Source> source,
                                       std::optional<ColorRange> range);
  // The same with the colors decided elsewhere: a rank of a distributed viewer colors its share as rank 0
  // colored its own (percentile ramps from rank 0's share), so that the composite is one process's frame.
  void setColors(std::optional<DisplayColorMode::Source> source, std::optional<ColorRange> range,
                 const DisplayColorMode& mode);
  const std::string& name() const override;
  const Bounds& bounds() const override;
  uint64_t pointCount() const override;
  bool streamed() const override { return false; }
  // Bytes of GPU memory of the layouts uploaded so far.
  uint64_t bytes() const override;
  const PointCloud& cloud() const { return cloud_; }
  // The color mode of the uploads (what a pick compares the drawn colors with).
  DisplayColorMode colors() const;
  FrameStats draw(Renderer& renderer, const Camera& camera, const RenderSettings& rs,
                  const ViewSettings& settings, std::string& status) override;

private:
  gpu::Context& context_;
  const PointCloud& cloud_;
  bool progress_;
  std::unique_ptr<GpuScene> scenes_[2];    // by SceneLayout
  std::optional<DisplayColorMode> colors_; // nullopt: displayColorMode(cloud)
  std::optional<DisplayColorMode::Source> colorSource_;
  std::optional<ColorRange> colorRange_;
};

class SceneView : public ContentSource {
public:
  // The source must outlive the view.
  SceneView(gpu::Context& context, SceneSource& source);
  ~SceneView() override;

  // Renders a frame; recreates the renderer when the viewport changed.
  FrameReport render(const Camera& camera, const ViewSettings& settings, Viewport viewport);
  Renderer& renderer() { return *renderer_; }
  bool hasRenderer() const { return renderer_ != nullptr; }

  // The point under a viewport position (the closest point within kPickRadius pixels, the nearest pixel
  // first), from the framebuffer words of a closest-point method (the current method when it is one).
  // The renderer's image is the current settings' again afterwards.
  std::optional<glm::dvec3> pick(const Camera& camera, const ViewSettings& settings, Viewport viewport,
                                 glm::dvec2 position);
  // The pick tool: the point of the cloud drawn closest within kPickRadius pixels of a viewport position
  // (the nearest pixel first), with every attribute the cloud holds, as render --pick reports it
  // (report/pick_json.h) plus "world": its position as a point of the measurements, when one was found.
  // An octree's point is the one the lod method drew there (report/pick_json.h), with "node" and its index
  // in the node. A "point" of "unavailable: ..." says why a frame cannot be picked from (stereo).
  nlohmann::json pickAttributes(const Camera& camera, const ViewSettings& settings, Viewport viewport,
                                glm::dvec2 position);
  // Draws the annotations over a mono frame `rgba` this view just rendered at `viewport` with `camera`,
  // depth-tested against the canonical words of a closest-point frame drawn for it (every method,
  // the LOD methods included). Nothing for a stereo frame or an empty list.
  void drawOverlay(const Camera& camera, const ViewSettings& settings, Viewport viewport,
                   const Annotations& annotations, std::vector<uint32_t>& rgba);
  // Linear depth of the point pick() would return, for zooming towards the cursor.
  std::optional<double> depthAt(const Camera& camera, const ViewSettings& settings, Viewport viewport,
                                glm::dvec2 position);

  // RGBA8 pixels (row 0 at the top) of a frame at the viewport's size, rendered at `supersample` times
  // the size and box-filtered down when supersample > 1.
  std::vector<uint32_t> screenshot(const Camera& camera, const ViewSettings& settings, Viewport viewport,
                                   uint32_t supersample);

  SceneSource& source() { return source_; }
  // Bytes of GPU memory of the uploaded scenes and this view's targets.
  uint64_t gpuBytes() const;

  // The level-of-detail hook: an octree source answers whether nodes are still arriving.
  bool changedSinceLastFrame() override { return source_.changed(); }

private:
  struct Picked {
    glm::dvec3 point;
    double depth;
  };
  void ensureRenderer(Viewport viewport, uint32_t eyes); // viewport: one eye's
  std::optional<Picked> pickPoint(const Camera& camera, const ViewSettings& settings, Viewport viewport,
                                  glm::dvec2 position);
  gpu::Context& context_;
  SceneSource& source_;
  std::unique_ptr<Renderer> renderer_;
};

// The session's input that needs the GPU, served the same way by every front end: wheel steps towards
// the depth under the cursor (read from the framebuffer, the pivot's plane over an empty pixel), and the
// pivot picked under a double-click (Requests::pick). pickPivot returns the picked point, if any.
void zoomAtCursor(Session& session, SceneView& view, glm::dvec2 position, double steps);
// The pick tool of every front end: the point under a position with its attributes
// (SceneView::pickAttributes); with a measuring kind (Distance, Height, Area) a picked point also becomes
// the next vertex of the session's open measurement.
nlohmann::json pickTool(Session& session, SceneView& view, glm::dvec2 position,
                        std::optional<AnnotationKind> measure);
std::optional<glm::dvec3> pickPivot(Session& session, SceneView& view, glm::dvec2 position);
// A measurement's vertex drawn within this many pixels of a press is grabbed by a Ctrl+drag.
constexpr double kVertexGrabPixels = 8;
// Moving a vertex, in every front end: the vertex of the session's measurements drawn nearest `from`
// (within kVertexGrabPixels) moves to the point picked at `to` (pickTool's pick, without measuring).
// Returns {"moved": whether it moved, "index" and "vertex" when one was grabbed, "pick": the pick at `to`}.
nlohmann::json moveVertexTool(Session& session, SceneView& view, glm::dvec2 from, glm::dvec2 to);

} // namespace pointrast::view

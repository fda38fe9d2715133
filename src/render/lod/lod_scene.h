// An octree on the GPU, streamed: the level-of-detail counterpart of GpuScene. It knows the part of the
// hierarchy read so far (hierarchy.h), chooses each frame's nodes (selection.h), has worker threads read and
// encode missing nodes from the NodeSource (node_readers.h) into host staging blocks, and copies them into a
// GPU node cache of pages (page_pool.h) within a byte budget, evicting the least recently used nodes. The
// octree may be far larger than GPU memory and than host memory: the host holds the known hierarchy, the
// staging blocks and one node per reader.
//
// Frame by frame (the viewers, and `render` until the selection is resident):
//   scene.update(camera, width, height, view);   // select; take what the readers finished; ask for more
//   record: scene.recordUploads(cmd), then draw scene.drawList() (LodPasses) in the same command buffer
//   after the submission finished: scene.uploadsFinished();
// A frame never waits for a reader: it draws the resident part of its selection, where a missing node's
// resident ancestors stand in for it (a node is drawn only under a drawn parent), and later frames refine.
// update() says whether the frame differs from the last one (new nodes, another camera): "did anything
// change", for a viewer to know when to draw again; converged() says whether it drew the whole selection.
//
// Offline (a full-detail render of a selection larger than the budget): selectAll() reads the hierarchy the
// selection needs, splitPasses() cuts it into passes that fit the cache, and makeResident() streams one
// pass in, waiting; each pass's drawList() numbers its points in the order of the whole selection, so passes
// compose into the image one pass would give (LodPasses).
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "cloud/cloud.h"
#include "gpu/shared_types.h"
#include "gpu/vulkan_api.h"
#include "render/camera.h"
#include "render/lod/hierarchy.h"
#include "render/lod/lod_stats.h"
#include "render/lod/selection.h"

namespace pointrast::gpu {
class Context;
}

namespace pointrast::lod {

class NodeEncoder;
class NodeReaders;
class PagePool;
class StagingBlocks;
struct ReadPoints;

struct LodOptions {
  uint64_t gpuBytes = 0;            // node cache budget; 0: defaultGpuBytes()
  uint32_t readers = 0;             // reader threads; 0: one per hardware thread
  uint64_t stagingBytes = 0;        // host staging for nodes read and not yet uploaded; 0: 256 MiB
  uint64_t uploadBytesPerFrame = 0; // node bytes one interactive frame copies at most; 0: 256 MiB
  // The readers' scheduling priority below the process's (nice): a viewer lowers it so that the threads
  // that draw, encode and send its frames never wait for a core behind the readers. 0: the same.
  int readerNiceness = 0;
  // How points become colors (render --color), decided once from the root's points; nullopt: the automatic
  // choice (node_encoding.h). Colors are computed as nodes are encoded, so every LOD method draws them.
  std::optional<DisplayColorMode::Source> colorSource;
  std::optional<ColorRange> colorRange; // intensity and elevation: the values at the ramp's ends
  // A distributed render or viewer (docs/mpi.md): selectAll() returns, and update() draws, share
  // `shareIndex` of `shares` of the whole selection (selection.h, shareOf), so that each rank draws its part
  // of every frame.
  uint32_t shareIndex = 0;
  uint32_t shares = 1;
};

// Half the device-local memory: the rest stays for framebuffers, the other methods and the driver.
uint64_t defaultGpuBytes(const gpu::Context& context);

// How a frame chooses its nodes.
struct LodView {
  double minNodePx = 100;   // LOD culling: smallest projected radius drawn, in pixels (selection.h)
  uint64_t pointBudget = 0; // most points a frame selects; 0: no limit
  Foveation foveation;      // larger nodes needed away from the image's centre (foveation.h)
};

// A frame's nodes for the GPU (shared.h): nodes in key order with their pages.
struct LodDrawList {
  std::vector<shared::LodNode> nodes;
  std::vector<shared::LodPage> pages;
  uint64_t points = 0;
};

class LodScene {
public:
  // Reads the root's points to decide the display colors (node_encoding.h) and starts the readers. Throws
  // InputError for a source whose metadata or root is unusable, UnsupportedError when the budget holds no
  // page.
  LodScene(gpu::Context& context, NodeSource& source, const LodOptions& options = {});
  ~LodScene();
  LodScene(const LodScene&) = delete;
  LodScene& operator=(const LodScene&) = delete;

  const OctreeMetadata& metadata() const;
  // The points' coordinates on the GPU are relative to origin() (the centre of the bounds), as a GpuScene's.
  const glm::dvec3& origin() const { return origin_; }
  const Bounds& bounds() const { return bounds_; } // the source's tight bounds (its cube when it has none)
  double nearW(const Camera& camera) const;

  // --- Frame by frame ---
  // Returns whether the draw list or the camera changed since the last update. Rethrows a reader's error.
  // `views`: the frame's camera, or a stereo frame's two eyes (one selection for both, selection.h); width x
  // height is one view's image.
  bool update(std::span<const Camera> views, uint32_t width, uint32_t height, const LodView& view);
  bool update(const Camera& camera, uint32_t width, uint32_t height, const LodView& view) {
    return update(std::span<const Camera>(&camera, 1), width, height, view);
  }
  bool converged() const { return converged_; }
  void recordUploads(VkCommandBuffer cmd) const; // the copies of this update's nodes, then a barrier
  void uploadsFinished();                        // their staging blocks are free again
  const LodDrawList& drawList() const { return drawList_; }
  const std::vector<uint32_t>& drawnNodes() const { return drawn_; } // hierarchy ids of drawList().nodes
  const LodStats& stats() const { return stats_; }
  const Hierarchy& hierarchy() const { return *hierarchy_; }
  NodeSource& source() const { return source_; }

  // --- Offline ---
  // The whole selection for a camera (no cache limit), after reading every hierarchy part it reaches.
  Selection selectAll(std::span<const Camera> views, uint32_t width, uint32_t height, const LodView& view);
  Selection selectAll(const Camera& camera, uint32_t width, uint32_t height, const LodView& view) {
    return selectAll(std::span<const Camera>(&camera, 1), width, height, view);
  }
  // The selection's nodes with points in key order, cut into passes that each fit the cache and hold fewer
  // than 2^32 points. Throws UnsupportedError for a node larger than the cache or the staging blocks.
  std::vector<std::vector<uint32_t>> splitPasses(const Selection& selection) const;
  // Streams `pass` (nodes in key order, as splitPasses cut them) into the cache, waiting; the draw list is
  // then the pass, its nodes ranked from rankBase on (the pass's first node's place in the whole selection).
  // Rethrows a reader's error.
  void makeResident(const std::vector<uint32_t>& pass, uint32_t rankBase);

private:
  struct Resident {
    std::vector<uint32_t> pages;
    Bounds bounds;
    uint64_t lastUsed = 0;
    std::list<uint32_t>::iterator lru;
  };
  void collect();
  void touch(uint32_t id);
  bool residentOrEmpty(uint32_t id) const;
  bool upload(ReadPoints& read);
  bool makeRoom(uint64_t pages);
  void uploadArrived(const std::vector<uint32_t>& wanted, uint64_t byteLimit);
  void request(const std::vector<uint32_t>& wanted, const std::vector<uint32_t>& expand);
  void buildDrawList(const std::vector<uint32_t>& nodes, uint32_t rankBase);
  void checkFits(uint32_t id) const;

  gpu::Context& context_;
  NodeSource& source_;
  LodOptions options_;
  glm::dvec3 origin_{0};
  Bounds bounds_;
  std::unique_ptr<Hierarchy> hierarchy_;
  std::unique_ptr<NodeEncoder> encoder_;
  std::unique_ptr<StagingBlocks> staging_;
  std::unique_ptr<PagePool> pool_;
  std::unique_ptr<NodeReaders> readers_; // last: its threads use the members above
  std::unordered_map<uint32_t, Resident> resident_;
  std::list<uint32_t> lru_;         // least recently used first
  std::vector<ReadPoints> arrived_; // read, not uploaded yet
  struct Copy {
    VkBuffer target;
    VkBufferCopy region;
  };
  std::vector<Copy> copies_;
  std::vector<uint32_t> copiedBlocks_; // staging blocks of copies_, free after the submission
  uint64_t frame_ = 0;
  LodDrawList drawList_;
  std::vector<uint32_t> drawn_; // ids of drawList_'s nodes, in its order
  std::vector<Camera> lastViews_;
  bool converged_ = false;
  LodStats stats_;
};

} // namespace pointrast::lod

// A point cloud on the GPU: float32 positions relative to an origin (rounded once from double) and RGBA8
// display colors, split into parts that each fit one buffer. A part is the unit of a dispatch, so scenes
// of billions of points (tens of GB) work on any device whatever its largest buffer or allocation.
#pragma once

#include <cstdint>
#include <vector>

#include "cloud/cloud.h"
#include "gpu/buffer.h"

namespace pointrast {

namespace gpu {
class Context;
}

struct ScenePart {
  gpu::Buffer positions; // float[3 * count]
  gpu::Buffer colors;    // uint[count]
  uint64_t first = 0;    // index of the part's first point in the source cloud
  uint64_t count = 0;
};

struct UploadOptions {
  uint64_t first = 0;          // upload points [first, first + count) of the cloud
  uint64_t count = UINT64_MAX; // clamped to the cloud's size
  uint64_t maxPartPoints = 0;  // 0: largest multiple of 10240 whose positions fit one buffer, <= 64 M
  bool progress = true;
};

class GpuScene {
public:
  // Uploads through a staging buffer; positions are relative to cloud.origin() whatever the subrange,
  // so scenes uploaded from parts of one cloud draw exactly the points the whole upload would.
  GpuScene(gpu::Context& context, const PointCloud& cloud, const UploadOptions& options = {});

  uint64_t pointCount() const { return pointCount_; }
  const glm::dvec3& origin() const { return origin_; }
  const Bounds& bounds() const { return bounds_; }
  const std::vector<ScenePart>& parts() const { return parts_; }
  // Bytes of point data in GPU memory (12 B position + 4 B color per point).
  uint64_t bytes() const { return pointCount_ * 16; }

private:
  std::vector<ScenePart> parts_;
  uint64_t pointCount_ = 0;
  glm::dvec3 origin_{0};
  Bounds bounds_;
};

} // namespace pointrast

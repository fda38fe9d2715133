// Picking: which point of a cloud in memory the renderer drew at a pixel. The renderer keeps, per pixel, the
// canonical word of the closest point (depth << 32 | color, Renderer::framebufferWords); the point is the
// one the image contract puts on that pixel (docs/design.md: the same projection, from the same float
// position relative to the origin), kept by the clip volumes, whose uploaded color is the word's and whose
// depth is nearest the word's. The scan is parallel over the cloud (~10 ms per 10 M points): a click's
// cost, not a frame's. render --pick and both viewers call it.
#pragma once

#include <cstdint>
#include <optional>

#include "cloud/cloud.h"
#include "cloud/point_filter.h"
#include "render/camera.h"
#include "render/renderer.h"

namespace pointrast {

struct PickRequest {
  const PointCloud* cloud = nullptr;  // the cloud the scenes were uploaded from (all of it)
  DisplayColorMode colors;            // the color mode of the upload
  std::optional<PointFilter> filter;  // RenderSettings::filter and UploadOptions::filter
  Camera camera;                      // the frame's camera (nearW 0: defaultNear of the cloud's bounds)
  uint32_t width = 0, height = 0;     // of the image
  DepthMode depth = DepthMode::Float; // how `word` encodes depth and color
};

// The index in the cloud of the point drawn at pixel (x, y) (row 0 at the top) whose canonical word is
// `word`; nullopt where the word is kEmptyPixel (background) or no point matches it.
std::optional<uint64_t> pickPoint(const PickRequest& request, uint32_t x, uint32_t y, uint64_t word);

} // namespace pointrast

// The CPU reference renderer: the image contract of docs/design.md evaluated in double precision, one point
// at a time, with the same framebuffer encoding as the GPU methods (float bits of the linear depth << 32 |
// RGBA8, minimum wins). It is the independent check of every GPU method.
#pragma once

#include <cstdint>
#include <vector>

#include "cloud/cloud.h"
#include "render/camera.h"

namespace pointrast {

// Framebuffer words (0xFFFFFFFFFFFFFFFF = empty) of the whole cloud seen by camera.
std::vector<uint64_t> referenceFramebuffer(const PointCloud& cloud, const Camera& camera, uint32_t width,
                                           uint32_t height);

// Resolve of framebuffer words to RGBA8 with a background color.
std::vector<uint32_t> resolveWords(const std::vector<uint64_t>& words, uint32_t background);

} // namespace pointrast

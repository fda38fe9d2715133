// Annotations drawn over a rendered image on the CPU: markers at measured points, lines between them,
// box and polygon outlines, and labels with the annotation's text and measured values in a built-in
// bitmap font. Lines and markers are depth-tested against the frame, pixel by pixel: where the frame's
// closest point is nearer (by more than the tolerance) the overlay is hidden. A label shows whole or not
// at all, by the test at its anchor. `render --annotations` draws them into its PNG and video frames; a
// viewer calls the same function on the image it reads back.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "cloud/annotations.h"
#include "render/camera.h"

namespace pointrast {

// The image drawn over, row 0 at the top, and the frame's canonical words (Renderer::framebufferWords:
// float linear depth << 32 | color, all ones where no point landed) for the depth test; empty words:
// no depth test.
struct OverlayTarget {
  std::span<uint32_t> rgba;
  uint32_t width = 0, height = 0;
  std::span<const uint64_t> words;
};

struct OverlayStyle {
  // Pixel size of lines and of the font: 0 chooses from the image (1 up to 1000 rows, 2 up to 2000, ...).
  uint32_t scale = 0;
  // An overlay pixel at linear depth w is hidden by a frame depth d when w > d * (1 + depthTolerance): a
  // measured point lies on the surface it was picked from and must not vanish into it.
  double depthTolerance = 0.01;
};

// Draws every annotation as seen by `camera` (its near plane nearW > 0: the renderer's, which resolves a
// camera's nearW of 0 to defaultNear of the scene's bounds). The annotations must be valid
// (annotationProblem empty). Mono cameras only: a stereo frame is two images.
void drawAnnotations(const OverlayTarget& target, const Camera& camera, double nearW,
                     const Annotations& annotations, const OverlayStyle& style = {});

// Text in the bitmap font with its top-left corner at (x, y), at an integer scale, over a dark backing
// box one scale unit wider on each side; clipped to the image. No depth test.
void drawText(const OverlayTarget& target, int x, int y, std::string_view utf8, uint32_t rgba, uint32_t scale);

} // namespace pointrast

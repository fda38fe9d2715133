// Shows a rendered frame in the window: one pass into the acquired swapchain image that copies the
// renderer's RGBA8 image (read by device address, never through the host) and draws the panel on top.
#pragma once

#include <cstdint>

#include "gpu/graphics.h"
#include "gpu/timer.h"
#include "view/desktop/panel_renderer.h"

struct ImDrawData;

namespace pointrast::gpu {
class Swapchain;
}

namespace pointrast::view {

struct ShownImage {
  uint64_t address = 0; // RGBA8, row 0 at the top (Renderer::imageAddress)
  uint32_t width = 0, height = 0;
};

class Presenter {
public:
  Presenter(gpu::Context& context, gpu::Swapchain& swapchain);

  struct Result {
    bool presented = false; // false: the swapchain is out of date, recreate it and present again
    double gpuMs = 0;       // GPU time of the pass (copy + panel), timestamp queries
  };
  // panel: the panel's draw data, or null when the panel is hidden.
  Result present(const ShownImage& image, const ImDrawData* panel);
  // The picture the panel shows with ImGui::Image(PanelRenderer::kImageId, ...).
  void setPanelImage(uint32_t width, uint32_t height, const uint32_t* rgba) {
    panel_.setImage(width, height, rgba);
  }

private:
  gpu::Context& context_;
  gpu::Swapchain& swapchain_;
  gpu::GraphicsProgram copy_;
  PanelRenderer panel_;
  gpu::TimestampPool timer_;
};

} // namespace pointrast::view

// Every frame a viewer rendered, kept for the statistics it writes when it closes (`view --stats`).
// Session::statistics holds medians of the last kStatsWindow frames for the panel; this holds them all, so
// that a run's median and tail cover the whole session (24 B a frame: an hour at 60 frames/s is 5 MiB).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "view/navigation.h"

namespace pointrast::view {

// The passes of one frame the viewer rendered, each timed by timestamp queries, and the host's wall clock
// around them. The passes run one after the other, each waited for, so renderMs + presentMs <= hostMs.
struct FrameTiming {
  double renderMs = 0;  // GPU: clear + draw + resolve of the points
  double presentMs = 0; // GPU: the image copied into the swapchain image, the panel drawn on it
  double hostMs = 0;    // wall clock from the start of the render to the image handed to the display
};

struct FrameLog {
  std::vector<FrameTiming> frames;
  std::vector<std::string> methods; // the methods the frames were drawn with, in order of first use
  std::vector<Viewport> sizes;      // the image sizes, in order of first use
  gpu::DeviceInfo device;
  uint64_t deviceLocalBytes = 0;
  double seconds = 0; // from the window's opening to its closing

  void add(const FrameTiming& timing, const std::string& method, Viewport size) {
    frames.push_back(timing);
    if (methods.empty() || methods.back() != method) addOnce(methods, method);
    if (sizes.empty() || !(sizes.back() == size)) addOnce(sizes, size);
  }

private:
  template <typename T> static void addOnce(std::vector<T>& list, const T& value) {
    for (const T& v : list)
      if (v == value) return;
    list.push_back(value);
  }
};

} // namespace pointrast::view

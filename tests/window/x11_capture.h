// Reading a window's pixels from an X server (Xvfb in the tests) with XGetImage: what the user sees, after
// the swapchain presented it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <X11/Xlib.h>
#include <X11/Xutil.h>

namespace pointrast::test {

struct Capture {
  uint32_t width = 0, height = 0;
  std::vector<uint32_t> rgba; // r | g << 8 | b << 16 | 255 << 24, row 0 at the top
};

// The window's contents (TrueColor visuals: 24-bit depth in 32-bit pixels); empty on failure.
inline Capture captureWindow(const std::string& display, unsigned long window) {
  Capture capture;
  Display* dpy = XOpenDisplay(display.c_str());
  if (!dpy) return capture;
  XWindowAttributes attributes{};
  if (XGetWindowAttributes(dpy, Window(window), &attributes)) {
    XImage* image = XGetImage(dpy, Window(window), 0, 0, unsigned(attributes.width),
                              unsigned(attributes.height), AllPlanes, ZPixmap);
    if (image) {
      capture.width = uint32_t(attributes.width);
      capture.height = uint32_t(attributes.height);
      capture.rgba.resize(size_t(capture.width) * capture.height);
      for (uint32_t y = 0; y < capture.height; ++y)
        for (uint32_t x = 0; x < capture.width; ++x) {
          unsigned long p = XGetPixel(image, int(x), int(y));
          uint32_t r = uint32_t((p & image->red_mask) >> __builtin_ctzl(image->red_mask));
          uint32_t g = uint32_t((p & image->green_mask) >> __builtin_ctzl(image->green_mask));
          uint32_t b = uint32_t((p & image->blue_mask) >> __builtin_ctzl(image->blue_mask));
          capture.rgba[size_t(y) * capture.width + x] = r | g << 8 | b << 16 | 0xFF000000u;
        }
      XDestroyImage(image);
    }
  }
  XCloseDisplay(dpy);
  return capture;
}

} // namespace pointrast::test

// JPEG encoding of rendered frames with libjpeg-turbo's TurboJPEG API (linked statically: the binary
// keeps no run-time dependency for it). One encoder per thread: a TurboJPEG handle is not thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace pointrast::view::web {

struct JpegOptions {
  int quality = 90;       // 1..100
  bool fullChroma = true; // 4:4:4; 4:2:0 otherwise (half the color resolution, smaller, faster)
  bool fastDct = false;   // the faster, slightly less accurate integer DCT
};

class JpegEncoder {
public:
  JpegEncoder();
  ~JpegEncoder();
  JpegEncoder(const JpegEncoder&) = delete;
  JpegEncoder& operator=(const JpegEncoder&) = delete;

  // Encodes RGBA8 pixels (r in the low byte, row 0 at the top; alpha ignored) into `out`, which is
  // resized to the JPEG's length; its capacity is reused from frame to frame.
  void encode(std::span<const uint32_t> rgba, uint32_t width, uint32_t height, const JpegOptions& options,
              std::vector<uint8_t>& out);

private:
  void* handle_;
};

// Decodes a JPEG into RGBA8 (alpha 255); for tests and tools. Returns false on a corrupt stream.
bool decodeJpeg(std::span<const uint8_t> jpeg, uint32_t& width, uint32_t& height,
                std::vector<uint32_t>& rgba);

} // namespace pointrast::view::web

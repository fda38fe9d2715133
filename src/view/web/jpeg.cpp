#include "view/web/jpeg.h"

#include <cassert>
#include <string>

#include <turbojpeg.h>

#include "base/error.h"

namespace pointrast::view::web {

JpegEncoder::JpegEncoder() : handle_(tjInitCompress()) {
  if (!handle_) throw std::runtime_error(std::string("TurboJPEG: ") + tjGetErrorStr2(nullptr));
}

JpegEncoder::~JpegEncoder() {
  tjDestroy(handle_);
}

void JpegEncoder::encode(std::span<const uint32_t> rgba, uint32_t width, uint32_t height,
                         const JpegOptions& options, std::vector<uint8_t>& out) {
  assert(rgba.size() == uint64_t(width) * height && options.quality >= 1 && options.quality <= 100);
  int subsampling = options.fullChroma ? TJSAMP_444 : TJSAMP_420;
  // The worst case TurboJPEG documents, allocated once: with TJFLAG_NOREALLOC it writes into our buffer.
  unsigned long capacity = tjBufSize(int(width), int(height), subsampling);
  if (out.size() < capacity) out.resize(capacity);
  unsigned char* data = out.data();
  unsigned long size = capacity;
  int flags = TJFLAG_NOREALLOC | (options.fastDct ? TJFLAG_FASTDCT : 0);
  // RGBA8 packed r | g << 8 | b << 16 | a << 24 is, in memory on a little-endian machine, R G B A: RGBX.
  if (tjCompress2(handle_, reinterpret_cast<const unsigned char*>(rgba.data()), int(width), 0, int(height),
                  TJPF_RGBX, &data, &size, subsampling, options.quality, flags) != 0)
    throw std::runtime_error(std::string("TurboJPEG: ") + tjGetErrorStr2(handle_));
  out.resize(size);
}

bool decodeJpeg(std::span<const uint8_t> jpeg, uint32_t& width, uint32_t& height,
                std::vector<uint32_t>& rgba) {
  tjhandle handle = tjInitDecompress();
  if (!handle) return false;
  int w = 0, h = 0, subsampling = 0, colorspace = 0;
  bool ok = tjDecompressHeader3(handle, jpeg.data(), jpeg.size(), &w, &h, &subsampling, &colorspace) == 0 &&
            w > 0 && h > 0;
  if (ok) {
    rgba.assign(size_t(w) * size_t(h), 0);
    ok = tjDecompress2(handle, jpeg.data(), jpeg.size(), reinterpret_cast<unsigned char*>(rgba.data()), w, 0,
                       h, TJPF_RGBA, 0) == 0;
    width = uint32_t(w);
    height = uint32_t(h);
  }
  tjDestroy(handle);
  return ok;
}

} // namespace pointrast::view::web

// PNG output through stb_image_write (libstb-dev), 8-bit RGB.
#include "io/io_util.h"
#include "io/writer.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC // private to this file: no symbol clash with another copy of stb
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_image_write.h>
#pragma GCC diagnostic pop

#include <climits>

namespace pointrast::io {

using namespace detail;

namespace {

struct Sink {
  PartialFile* file = nullptr;
  bool failed = false;
  std::string error;
};

void writeToSink(void* context, void* data, int size) {
  auto* sink = static_cast<Sink*>(context);
  if (sink->failed) return;
  try {
    sink->file->write(data, static_cast<size_t>(size));
  } catch (const InputError& e) { // stb is C: no exception may cross it
    sink->failed = true;
    sink->error = e.what();
  }
}

// stb takes int sizes and builds the whole filtered image in memory.
bool encodable(uint32_t width, uint32_t height) {
  return width > 0 && height > 0 && uint64_t(width) * height * 3 <= uint64_t(INT_MAX) / 2;
}

std::vector<uint8_t> toRgb(uint32_t width, uint32_t height, const uint32_t* rgba) {
  std::vector<uint8_t> rgb(size_t(width) * height * 3);
  for (size_t i = 0; i < size_t(width) * height; ++i) {
    rgb[3 * i] = static_cast<uint8_t>(rgba[i]);
    rgb[3 * i + 1] = static_cast<uint8_t>(rgba[i] >> 8);
    rgb[3 * i + 2] = static_cast<uint8_t>(rgba[i] >> 16);
  }
  return rgb;
}

} // namespace

void writePng(const std::filesystem::path& path, uint32_t width, uint32_t height, const uint32_t* rgba) {
  if (!encodable(width, height)) fail(path, strFormat("cannot write a %u x %u PNG", width, height));
  std::vector<uint8_t> rgb = toRgb(width, height, rgba);
  PartialFile out(path);
  Sink sink;
  sink.file = &out;
  int ok = stbi_write_png_to_func(writeToSink, &sink, static_cast<int>(width), static_cast<int>(height), 3,
                                  rgb.data(), static_cast<int>(width * 3));
  if (sink.failed) throw InputError(sink.error);
  if (!ok) fail(path, "PNG encoding failed (out of memory?)");
  out.commit();
}

std::vector<uint8_t> encodePng(uint32_t width, uint32_t height, const uint32_t* rgba) {
  if (!encodable(width, height)) throw InputError(strFormat("cannot encode a %u x %u PNG", width, height));
  std::vector<uint8_t> rgb = toRgb(width, height, rgba);
  std::vector<uint8_t> png;
  auto append = [](void* context, void* data, int size) {
    auto* bytes = static_cast<const uint8_t*>(data);
    static_cast<std::vector<uint8_t>*>(context)->insert(static_cast<std::vector<uint8_t>*>(context)->end(),
                                                        bytes, bytes + size);
  };
  int ok = stbi_write_png_to_func(append, &png, static_cast<int>(width), static_cast<int>(height), 3,
                                  rgb.data(), static_cast<int>(width * 3));
  if (!ok) throw InputError("PNG encoding failed (out of memory?)");
  return png;
}

} // namespace pointrast::io

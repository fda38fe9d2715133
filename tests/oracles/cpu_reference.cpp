#include "oracles/cpu_reference.h"

#include <atomic>
#include <bit>
#include <cmath>

#include "base/parallel.h"

namespace pointrast {

std::vector<uint64_t> referenceFramebuffer(const PointCloud& cloud, const Camera& camera, uint32_t width,
                                           uint32_t height) {
  validateCamera(camera);
  std::vector<std::atomic<uint64_t>> fb(uint64_t(width) * height);
  for (auto& w : fb)
    w.store(~0ull, std::memory_order_relaxed);
  glm::dvec3 origin = cloud.origin();
  glm::dmat4 m = viewProjection(camera, origin, double(width) / double(height));
  double nearW = camera.nearW > 0 ? camera.nearW : defaultNear(cloud.bounds);
  parallelBlocks(cloud.size(), 1 << 16, [&](uint64_t, uint64_t begin, uint64_t end) {
    std::vector<uint32_t> colors(end - begin);
    displayColors(colors.data(), cloud, begin, end - begin);
    for (uint64_t i = begin; i < end; ++i) {
      glm::dvec4 c = m * glm::dvec4(cloud.world(i) - origin, 1.0);
      if (!(c.w > nearW)) continue;
      double fx = (c.x / c.w + 1.0) * 0.5 * width;
      double fy = (1.0 - c.y / c.w) * 0.5 * height;
      if (!(fx >= 0 && fx < width && fy >= 0 && fy < height)) continue;
      uint64_t pixel = uint64_t(std::floor(fy)) * width + uint64_t(std::floor(fx));
      uint64_t word = (uint64_t(std::bit_cast<uint32_t>(float(c.w))) << 32) | colors[i - begin];
      uint64_t old = fb[pixel].load(std::memory_order_relaxed);
      while (word < old && !fb[pixel].compare_exchange_weak(old, word, std::memory_order_relaxed)) {
      }
    }
  });
  std::vector<uint64_t> words(fb.size());
  for (size_t i = 0; i < fb.size(); ++i)
    words[i] = fb[i].load(std::memory_order_relaxed);
  return words;
}

std::vector<uint32_t> resolveWords(const std::vector<uint64_t>& words, uint32_t background) {
  std::vector<uint32_t> image(words.size());
  for (size_t i = 0; i < words.size(); ++i)
    image[i] = words[i] == ~0ull ? background : uint32_t(words[i]);
  return image;
}

} // namespace pointrast

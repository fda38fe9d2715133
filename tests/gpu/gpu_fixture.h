// A Vulkan context with the validation layer on for every GPU test; a validation error fails the test.
#pragma once

#include <cstdlib>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "cloud/cloud.h"
#include "gpu/context.h"
#include "render/camera.h"

namespace pointrast::test {

// One context for the whole test binary, made by the first GPU test. A context per test meant hundreds of
// instances and devices: slow on lavapipe, and on the H200 the NVIDIA driver refused vkCreateInstance
// after about 30 of them. Each test checks that it added no validation error of its own.
class GpuTest : public ::testing::Test {
protected:
  void SetUp() override {
    static std::unique_ptr<gpu::Context> shared = [] {
      gpu::ContextOptions options;
      // On unless POINTRAST_VALIDATION=0 (a machine without the layer installed).
      const char* env = std::getenv("POINTRAST_VALIDATION");
      options.validation = !(env && std::string(env) == "0");
      options.announce = false;
      return std::make_unique<gpu::Context>(options);
    }();
    context = shared.get();
    errorsBefore = context->validationErrors();
  }
  void TearDown() override {
    if (!context) return; // the context could not be made: SetUp failed the test already
    EXPECT_EQ(context->validationErrors(), errorsBefore)
        << "the validation layer reported errors (see stderr)";
  }
  gpu::Context* context = nullptr;
  uint32_t errorsBefore = 0;
};

// A cloud from world points and RGBA8 colors, quantized at `scale` around `offset`; bounds computed.
inline PointCloud cloudFromPoints(const std::vector<glm::dvec3>& points, const std::vector<uint32_t>& colors,
                                  double scale = 1e-4, glm::dvec3 offset = glm::dvec3(0)) {
  PointCloud cloud;
  cloud.scale = glm::dvec3(scale);
  cloud.offset = offset;
  for (const glm::dvec3& p : points) {
    glm::dvec3 q = (p - offset) / scale;
    cloud.positions.insert(cloud.positions.end(), {int32_t(std::llround(q.x)), int32_t(std::llround(q.y)),
                                                   int32_t(std::llround(q.z))});
  }
  cloud.colors = colors;
  computeBounds(cloud);
  return cloud;
}

// `count` points uniform in the box [-half, half] with random opaque colors, drawing from rng in the order
// x, y, z, color per point (callers may go on using rng afterwards).
inline PointCloud randomBoxCloud(std::mt19937_64& rng, size_t count, glm::dvec3 half) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<glm::dvec3> points(count);
  std::vector<uint32_t> colors(count);
  for (size_t i = 0; i < count; ++i) {
    points[i] = {u(rng) * half.x, u(rng) * half.y, u(rng) * half.z};
    colors[i] = 0xFF000000u | uint32_t(rng() & 0xFFFFFF);
  }
  return cloudFromPoints(points, colors);
}

// Camera at the origin looking down -z with a 90 degree field of view: a point (x, y, -d) lands at
// px = floor((x/d + 1) / 2 * W), py = floor((1 - y/d) / 2 * H).
inline Camera axisCamera() {
  Camera c;
  c.eye = {0, 0, 0};
  c.target = {0, 0, -1};
  c.up = {0, 1, 0};
  c.fovY = 90;
  c.nearW = 0.01;
  return c;
}

} // namespace pointrast::test

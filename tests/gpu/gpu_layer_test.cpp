#include <cstring>
#include <numeric>

#include "gpu/buffer.h"
#include "gpu/program.h"
#include "gpu/shader_registry.h"
#include "gpu/shared_types.h"
#include "gpu_fixture.h"

namespace pointrast::test {

TEST(SpirvReflection, PushConstantSizesMatchSharedStructs) {
  EXPECT_EQ(gpu::reflectSpirv(gpu::findShader("raster_closest.comp")).pushConstantSize,
            sizeof(shared::RasterPush));
  EXPECT_EQ(gpu::reflectSpirv(gpu::findShader("resolve.comp")).pushConstantSize, sizeof(shared::ResolvePush));
}

TEST(SpirvReflection, LocalSizesMatchSharedConstants) {
  EXPECT_EQ(gpu::reflectSpirv(gpu::findShader("raster_closest.comp")).localSize[0], shared::kPointGroupSize);
  EXPECT_EQ(gpu::reflectSpirv(gpu::findShader("resolve.comp")).localSize[0], shared::kPixelGroupSize);
}

TEST(Grid, CoversEveryItemWithRowsOfAtMost65535Groups) {
  for (uint64_t items :
       {0ull, 1ull, 127ull, 128ull, 129ull, 65535ull * 128, 65535ull * 128 + 1, 1ull << 32}) {
    gpu::Grid g = gpu::gridFor(items, 128);
    EXPECT_LE(g.x, 65535u);
    uint64_t covered = uint64_t(g.x) * g.y * 128;
    EXPECT_GE(covered, items);
    if (items) {
      EXPECT_LT(covered - items, uint64_t(g.x) * 128 + 128) << items; // at most one spare row
    }
  }
}

TEST_F(GpuTest, ContextReportsDevice) {
  EXPECT_FALSE(context->info().name.empty());
  EXPECT_GT(context->subgroupSize(), 0u);
  EXPECT_GT(context->maxAllocationSize(), 0u);
  EXPECT_TRUE(context->validationEnabled());
}

TEST_F(GpuTest, BufferFillAndReadBack) {
  gpu::Buffer buffer(*context, 1 << 20, gpu::kBufferUsage, gpu::MemoryKind::Device, "test buffer");
  EXPECT_NE(buffer.address(), 0u);
  context->submitAndWait(
      [&](VkCommandBuffer cmd) { gpu::vkCmdFillBuffer(cmd, buffer.handle(), 0, 1 << 20, 0xA5A5A5A5u); });
  std::vector<uint32_t> data(1 << 18);
  gpu::readBuffer(*context, buffer, 0, data.data(), 1 << 20);
  EXPECT_TRUE(std::all_of(data.begin(), data.end(), [](uint32_t v) { return v == 0xA5A5A5A5u; }));
}

TEST_F(GpuTest, OversizedBufferIsAClearError) {
  EXPECT_THROW(gpu::Buffer(*context, uint64_t(1) << 62, gpu::kBufferUsage, gpu::MemoryKind::Device, "huge"),
               std::runtime_error);
}

} // namespace pointrast::test

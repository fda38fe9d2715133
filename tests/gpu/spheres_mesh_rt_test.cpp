// sphere-mesh-points, sphere-mesh-tris (VK_EXT_mesh_shader) and sphere-rt (VK_KHR_ray_tracing_pipeline).
//
// Everywhere, also on lavapipe, which has neither extension: the embedded SPIR-V of every new shader is
// valid (spirv-val) and declares the stage, entry point, push constants and mesh outputs the host code
// assumes; the host arithmetic (mesh draw splitting, mesh-shader limits, shader binding table layout) and
// the AABB pass of sphere-rt (a compute shader) are checked; a device without the extensions refuses the
// methods with the reason, and bad settings are refused before any device work.
// Where the device has the extensions: every variant agrees with the CPU ray caster with the contract of
// the other sphere pipelines (>= 99 % of pixels, depth within 1e-5 relative away from silhouettes), also
// for spheres across the image border and a sphere larger than the largest point (sphere-mesh-points
// reports its clipping like sphere-points); otherwise those tests are skipped with the reason printed.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <ostream>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <unistd.h>

#include "base/error.h"
#include "gpu/buffer.h"
#include "gpu/context.h"
#include "gpu/ray_tracing.h"
#include "gpu/shader_registry.h"
#include "gpu/shared_types.h"
#include "gpu/spirv_reflect.h"
#include "render/spheres/sphere_mesh.h"
#include "render/spheres/sphere_rt.h"
#include "spheres_test_util.h"

namespace pointrast::test {

namespace {

bool startsWith(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

// The execution model a module named name.stage must declare.
uint32_t expectedModel(std::string_view name) {
  std::string_view stage = name.substr(name.rfind('.') + 1);
  if (stage == "mesh") return gpu::kSpirvMesh;
  if (stage == "task") return gpu::kSpirvTask;
  if (stage == "rgen") return gpu::kSpirvRayGeneration;
  if (stage == "rint") return gpu::kSpirvIntersection;
  if (stage == "rchit") return gpu::kSpirvClosestHit;
  if (stage == "rmiss") return gpu::kSpirvMiss;
  if (stage == "comp") return gpu::kSpirvCompute;
  if (stage == "frag") return gpu::kSpirvFragment;
  return ~0u;
}

// Runs spirv-val on the words; "" when valid or when spirv-val is not installed (*ran says which).
std::string spirvValidate(std::span<const uint32_t> words, const std::string& name, bool* ran) {
  *ran = std::system("command -v spirv-val >/dev/null 2>&1") == 0;
  if (!*ran) return "";
  auto dir = std::filesystem::temp_directory_path() / ("pointrast_spirv_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto file = dir / (name + ".spv"), log = dir / (name + ".log");
  {
    std::ofstream out(file, std::ios::binary);
    out.write(reinterpret_cast<const char*>(words.data()), std::streamsize(words.size_bytes()));
  }
  std::string command =
      "spirv-val --target-env vulkan1.3 '" + file.string() + "' >'" + log.string() + "' 2>&1";
  int status = std::system(command.c_str());
  std::ifstream in(log);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove_all(dir);
  return status == 0 ? "" : (text.empty() ? "spirv-val failed" : text);
}

} // namespace

// --- SPIR-V of the new shaders (no device needed) ----------------------------------------------------------

TEST(SphereMeshRtShaders, EveryVariantIsEmbedded) {
  for (uint32_t meshlet : {shared::kSphereMeshletLarge, shared::kSphereMeshletSmall})
    for (bool points : {true, false})
      for (bool task : {false, true})
        EXPECT_FALSE(gpu::findShader(meshShaderName(meshlet, points, task)).empty());
  for (const char* name : {"sphere_mesh.task", "sphere_rt.rgen", "sphere_rt.rmiss", "sphere_rt.rint",
                           "sphere_rt.rchit", "sphere_rt_aabbs.comp", "sphere_impostor.frag"})
    EXPECT_FALSE(gpu::findShader(name).empty()) << name;
}

TEST(SphereMeshRtShaders, ValidAndAsTheHostCodeAssumes) {
  size_t checked = 0;
  bool validatorRan = false;
  for (const gpu::EmbeddedShader& shader : gpu::embeddedShaders()) {
    std::string name(shader.name);
    if (!startsWith(name, "sphere_mesh") && !startsWith(name, "sphere_rt")) continue;
    ++checked;
    SCOPED_TRACE(name);
    bool ran = false;
    EXPECT_EQ(spirvValidate(shader.words, name, &ran), "");
    validatorRan = validatorRan || ran;
    gpu::SpirvReflection r = gpu::reflectSpirv(shader.words);
    EXPECT_EQ(r.executionModel, expectedModel(name));
    EXPECT_EQ(r.entryPoint, "main");
    EXPECT_TRUE(std::find(r.specIds.begin(), r.specIds.end(), 0u) != r.specIds.end() ||
                name == "sphere_rt.rchit" || name == "sphere_rt.rmiss" || name == "sphere_rt.rgen")
        << "LAYOUT (constant 0) missing";
    if (r.executionModel == gpu::kSpirvMesh) {
      // sphere_mesh_{points,tris}{31,15}[_task].mesh
      bool points = startsWith(name, "sphere_mesh_points");
      uint32_t meshlet = uint32_t(std::stoul(name.substr(points ? 18 : 16, 2)));
      EXPECT_TRUE(meshlet == shared::kSphereMeshletLarge || meshlet == shared::kSphereMeshletSmall);
      EXPECT_EQ(r.localSize[0], meshlet);
      EXPECT_EQ(r.outputVertices, meshOutputVertices(meshlet, points));
      EXPECT_EQ(r.outputPrimitives, meshOutputPrimitives(meshlet, points));
      EXPECT_EQ(r.outputTopology, points ? gpu::kSpirvOutputPoints : gpu::kSpirvOutputTriangles);
      // (The built-in block declares gl_PointSize in every mesh shader; points must have it.)
      if (points) {
        EXPECT_TRUE(r.usesPointSize) << "a mesh shader drawing points must write gl_PointSize";
      }
      EXPECT_EQ(r.pushConstantSize, sizeof(shared::SpherePush));
      EXPECT_TRUE(std::find(r.specIds.begin(), r.specIds.end(), 2u) != r.specIds.end()) << "BILLBOARD";
    } else if (r.executionModel == gpu::kSpirvTask) {
      EXPECT_EQ(r.localSize[0], shared::kSphereTaskGroupSize);
      EXPECT_EQ(r.pushConstantSize, sizeof(shared::SpherePush));
      EXPECT_TRUE(std::find(r.specIds.begin(), r.specIds.end(), 1u) != r.specIds.end()) << "MESHLET";
    } else if (name == "sphere_rt_aabbs.comp") {
      EXPECT_EQ(r.pushConstantSize, sizeof(shared::SphereAabbPush));
      EXPECT_EQ(r.localSize[0], shared::kSphereGroupSize);
    } else if (name == "sphere_rt.rgen" || name == "sphere_rt.rint") {
      EXPECT_EQ(r.pushConstantSize, sizeof(shared::SphereRtPush));
    } else {
      // Miss and closest hit need no constants; a block they declare is the same one.
      EXPECT_TRUE(r.pushConstantSize == 0 || r.pushConstantSize == sizeof(shared::SphereRtPush));
    }
  }
  EXPECT_EQ(checked, 8u + 1u + 4u + 1u); // mesh variants, task, ray tracing stages, AABB pass
  if (!validatorRan) std::printf("note: spirv-val is not installed; only the build validated the modules\n");
}

// --- Host arithmetic (no device needed)
// ----------------------------------------------------------------------

TEST(SphereMeshPlan, SmallPartsAreOneDraw) {
  EXPECT_TRUE(planMeshDraws(0, 31, 1u << 22, 65535, 65535).empty());
  std::vector<MeshDraw> d = planMeshDraws(100, 31, 1u << 22, 65535, 65535);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].firstGroup, 0u);
  EXPECT_EQ(d[0].groupsX, 4u); // ceil(100 / 31)
  EXPECT_EQ(d[0].groupsY, 1u);
  d = planMeshDraws(31, 31, 1u << 22, 65535, 65535);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].groupsX, 1u);
}

TEST(SphereMeshPlan, EveryWorkgroupExactlyOnceWithinTheLimits) {
  // Random small limits, enumerating what the shaders compute: firstGroup + y * groupsX + x.
  std::mt19937 rng(5);
  for (int trial = 0; trial < 400; ++trial) {
    uint32_t perGroup = 1 + rng() % 40, maxTotal = 1 + rng() % 50, maxX = 1 + rng() % 12,
             maxY = 1 + rng() % 7;
    uint64_t count = rng() % 5000;
    uint64_t groups = (count + perGroup - 1) / perGroup;
    std::vector<int> seen(groups, 0);
    uint64_t next = 0;
    for (const MeshDraw& d : planMeshDraws(count, perGroup, maxTotal, maxX, maxY)) {
      ASSERT_GE(d.groupsX, 1u);
      ASSERT_GE(d.groupsY, 1u);
      ASSERT_LE(d.groupsX, maxX);
      ASSERT_LE(d.groupsY, maxY);
      ASSERT_LE(uint64_t(d.groupsX) * d.groupsY, maxTotal);
      ASSERT_EQ(d.firstGroup, next) << "draws follow each other";
      for (uint32_t y = 0; y < d.groupsY; ++y)
        for (uint32_t x = 0; x < d.groupsX; ++x) {
          uint64_t g = d.firstGroup + uint64_t(y) * d.groupsX + x;
          ASSERT_LT(g, groups) << "no workgroup past the last";
          ++seen[g];
        }
      next += uint64_t(d.groupsX) * d.groupsY;
    }
    EXPECT_EQ(next, groups);
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
  }
}

TEST(SphereMeshPlan, LargestPartAtTheGuaranteedLimits) {
  // A part of 64 M spheres in meshlets of 15 is 4,473,925 workgroups: more than one draw may launch at
  // VK_EXT_mesh_shader's guaranteed minimum (2^22 in all, 65535 per dimension).
  uint64_t count = 64ull << 20;
  for (uint32_t perGroup :
       {shared::kSphereMeshletSmall, shared::kSphereMeshletLarge, shared::kSphereTaskSpheres}) {
    std::vector<MeshDraw> draws = planMeshDraws(count, perGroup, 1u << 22, 65535, 65535);
    uint64_t total = 0;
    for (const MeshDraw& d : draws) {
      EXPECT_LE(uint64_t(d.groupsX) * d.groupsY, 1u << 22);
      EXPECT_LE(d.groupsX, 65535u);
      EXPECT_LE(d.groupsY, 65535u);
      total += uint64_t(d.groupsX) * d.groupsY;
    }
    EXPECT_EQ(total, (count + perGroup - 1) / perGroup);
    EXPECT_LE(draws.size(), 4u);
  }
}

namespace {

// VK_EXT_mesh_shader's required minimum limits, with NVIDIA's output granularity.
VkPhysicalDeviceMeshShaderPropertiesEXT minimumMeshLimits() {
  VkPhysicalDeviceMeshShaderPropertiesEXT l{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_PROPERTIES_EXT};
  l.maxTaskWorkGroupTotalCount = 1u << 22;
  l.maxTaskWorkGroupCount[0] = l.maxTaskWorkGroupCount[1] = l.maxTaskWorkGroupCount[2] = 65535;
  l.maxTaskWorkGroupInvocations = 128;
  l.maxTaskWorkGroupSize[0] = l.maxTaskWorkGroupSize[1] = l.maxTaskWorkGroupSize[2] = 128;
  l.maxTaskPayloadSize = 16384;
  l.maxTaskSharedMemorySize = 32768;
  l.maxTaskPayloadAndSharedMemorySize = 32768;
  l.maxMeshWorkGroupTotalCount = 1u << 22;
  l.maxMeshWorkGroupCount[0] = l.maxMeshWorkGroupCount[1] = l.maxMeshWorkGroupCount[2] = 65535;
  l.maxMeshWorkGroupInvocations = 128;
  l.maxMeshWorkGroupSize[0] = l.maxMeshWorkGroupSize[1] = l.maxMeshWorkGroupSize[2] = 128;
  l.maxMeshSharedMemorySize = 28672;
  l.maxMeshPayloadAndSharedMemorySize = 28672;
  l.maxMeshOutputMemorySize = 32768;
  l.maxMeshPayloadAndOutputMemorySize = 47104;
  l.maxMeshOutputComponents = 128;
  l.maxMeshOutputVertices = 256;
  l.maxMeshOutputPrimitives = 256;
  l.maxMeshOutputLayers = 8;
  l.maxMeshMultiviewViewCount = 1;
  l.meshOutputPerVertexGranularity = 32;
  l.meshOutputPerPrimitiveGranularity = 32;
  return l;
}

} // namespace

TEST(SphereMeshLimits, EveryVariantFitsTheGuaranteedMinimum) {
  VkPhysicalDeviceMeshShaderPropertiesEXT limits = minimumMeshLimits();
  for (uint32_t meshlet : {shared::kSphereMeshletLarge, shared::kSphereMeshletSmall})
    for (bool points : {true, false})
      for (bool task : {false, true}) {
        std::string why;
        EXPECT_TRUE(meshletFits(limits, meshlet, points, task, &why))
            << meshlet << " " << points << ": " << why;
      }
}

TEST(SphereMeshLimits, SmallLimitsAreNamed) {
  VkPhysicalDeviceMeshShaderPropertiesEXT limits = minimumMeshLimits();
  limits.maxMeshOutputVertices = 64;
  std::string why;
  EXPECT_FALSE(meshletFits(limits, 31, /* points= */ false, false, &why));
  EXPECT_EQ(why, "maxMeshOutputVertices is 64, the pipeline needs 124");
  EXPECT_TRUE(meshletFits(limits, 15, false, false, &why)) << why; // 60 vertices
  EXPECT_TRUE(meshletFits(limits, 31, /* points= */ true, false, &why)) << why;
  limits = minimumMeshLimits();
  limits.maxTaskPayloadSize = 256;
  EXPECT_TRUE(meshletFits(limits, 31, false, false, &why)) << why;
  EXPECT_FALSE(meshletFits(limits, 31, false, /* task= */ true, &why));
  EXPECT_NE(why.find("maxTaskPayloadSize"), std::string::npos) << why;
  VkPhysicalDeviceMeshShaderPropertiesEXT none{}; // a device without the extension
  EXPECT_FALSE(meshletFits(none, 15, true, false, &why));
}

TEST(SphereRtTable, LayoutFollowsTheAlignmentRules) {
  struct Case {
    uint32_t handleSize, handleAlignment, baseAlignment;
  };
  // NVIDIA (32, 32, 64), AMD (32, 32, 64 too), and made-up devices with larger alignments.
  for (Case c : {Case{32, 32, 64}, Case{32, 64, 256}, Case{16, 32, 32}, Case{64, 32, 64}, Case{32, 1, 1}}) {
    gpu::ShaderBindingTableLayout t =
        gpu::shaderBindingTableLayout(c.handleSize, c.handleAlignment, c.baseAlignment, 1, 1);
    SCOPED_TRACE(std::to_string(c.handleSize) + " " + std::to_string(c.handleAlignment) + " " +
                 std::to_string(c.baseAlignment));
    EXPECT_GE(t.stride, c.handleSize);
    EXPECT_EQ(t.stride % c.handleAlignment, 0u);
    EXPECT_EQ(t.rayGenSize, t.stride) << "vkCmdTraceRaysKHR: ray generation size == stride";
    for (uint64_t offset : {t.rayGenOffset, t.missOffset, t.hitOffset})
      EXPECT_EQ(offset % c.baseAlignment, 0u);
    EXPECT_GE(t.missOffset, t.rayGenOffset + t.rayGenSize);
    EXPECT_GE(t.hitOffset, t.missOffset + t.missSize);
    EXPECT_EQ(t.size, t.hitOffset + t.hitSize);
  }
  gpu::ShaderBindingTableLayout nvidia = gpu::shaderBindingTableLayout(32, 32, 64, 1, 1);
  EXPECT_EQ(nvidia.missOffset, 64u);
  EXPECT_EQ(nvidia.hitOffset, 128u);
  EXPECT_EQ(nvidia.size, 160u);
  EXPECT_EQ(gpu::alignUp(0, 128), 0u);
  EXPECT_EQ(gpu::alignUp(1, 128), 128u);
  EXPECT_EQ(gpu::alignUp(256, 128), 256u);
  EXPECT_EQ(gpu::alignUp(257, 1), 257u);
}

// --- On every device --------------------------------------------------------------------------------------

class SphereMeshRtDeviceTest : public GpuTest {};

TEST_F(SphereMeshRtDeviceTest, FeaturesMatchTheExtensionsAndMethodsSayWhyNot) {
  const gpu::DeviceFeatures& f = context->features();
  std::printf("'%s': mesh shaders %s (task shaders %s), ray tracing %s\n", context->info().name.c_str(),
              f.meshShader ? "yes" : "no", f.taskShader ? "yes" : "no", f.rayTracing ? "yes" : "no");
  if (f.meshShader) {
    EXPECT_GE(context->meshShaderProperties().maxMeshOutputVertices, 256u);
    EXPECT_NE(gpu::vkCmdDrawMeshTasksEXT, nullptr);
  } else {
    EXPECT_EQ(context->meshShaderProperties().maxMeshOutputVertices, 0u);
    EXPECT_EQ(gpu::vkCmdDrawMeshTasksEXT, nullptr);
  }
  if (f.rayTracing) {
    EXPECT_GE(context->rayTracingProperties().shaderGroupHandleSize, 1u);
    EXPECT_GE(context->accelerationStructureProperties().minAccelerationStructureScratchOffsetAlignment, 1u);
    EXPECT_NE(gpu::vkCmdTraceRaysKHR, nullptr);
  } else {
    EXPECT_EQ(gpu::vkCmdTraceRaysKHR, nullptr);
  }
  struct Expect {
    SphereMethod method;
    bool available;
    const char* reason;
  };
  for (Expect e : {Expect{SphereMethod::MeshPoints, f.meshShader && f.largePoints, "VK_EXT_mesh_shader"},
                   Expect{SphereMethod::MeshTriangles, f.meshShader, "VK_EXT_mesh_shader"},
                   Expect{SphereMethod::RayTracing, f.rayTracing, "VK_KHR_ray_tracing_pipeline"}}) {
    std::string why;
    bool supported = SphereRenderer::supports(*context, e.method, &why);
    if (e.available && !supported) {
      std::printf("%s\n", why.c_str()); // a limit too small: the reason names it
      EXPECT_NE(why.find("limits"), std::string::npos) << why;
      continue;
    }
    EXPECT_EQ(supported, e.available) << sphereMethodName(e.method);
    if (supported) continue;
    std::printf("%s\n", why.c_str());
    EXPECT_NE(why.find(sphereMethodName(e.method)), std::string::npos) << why;
    if (f.largePoints || e.method != SphereMethod::MeshPoints) {
      EXPECT_NE(why.find(e.reason), std::string::npos) << why;
    }
    // render() refuses with the same sentence.
    ParticleSet set = makeSet({{{0, 0, -5}, 1, 0xFFFFFFFFu}});
    SphereSettings settings;
    settings.method = e.method;
    try {
      renderGpu(*context, set, axisCamera(), 32, 32, {}, settings);
      ADD_FAILURE() << "render() drew with an unsupported method";
    } catch (const UnsupportedError& error) {
      EXPECT_EQ(std::string(error.what()), why);
    }
  }
}

TEST_F(SphereMeshRtDeviceTest, MeshSettingsAreCheckedFirst) {
  ParticleSet set = makeSet({{{0, 0, -5}, 1, 0xFFFFFFFFu}});
  SphereSettings settings;
  settings.method = SphereMethod::MeshTriangles;
  settings.meshlet = 16;
  EXPECT_THROW(renderGpu(*context, set, axisCamera(), 32, 32, {}, settings), InputError);
  settings.method = SphereMethod::Compute; // meshlets and task culling mean nothing to the others
  settings.meshlet = shared::kSphereMeshletSmall;
  EXPECT_THROW(renderGpu(*context, set, axisCamera(), 32, 32, {}, settings), InputError);
  settings.meshlet = shared::kSphereMeshletLarge;
  settings.taskCull = true;
  EXPECT_THROW(renderGpu(*context, set, axisCamera(), 32, 32, {}, settings), InputError);
  settings.method = SphereMethod::RayTracing;
  EXPECT_THROW(renderGpu(*context, set, axisCamera(), 32, 32, {}, settings), InputError);
}

TEST_F(SphereMeshRtDeviceTest, AabbPassBoundsEverySphereInEveryLayout) {
  // sphere-rt's acceleration-structure input, computed by a compute shader (which lavapipe runs): every
  // valid sphere lies in its box with at most the documented padding around it; spheres every method
  // culls for their values get an inactive box (min.x NaN). Several parts, as a large set has.
  std::vector<SphereSpec> spheres = randomSpheres(2000, 23, 50, 0.01, 3);
  spheres[7].radius = 0;
  spheres[100].radius = -1;
  spheres[1500].radius = std::numeric_limits<double>::infinity();
  ParticleSet perParticle = makeSet(spheres), global = makeSet(spheres, true, true);
  global.globalRadius = 0.75f;
  gpu::Buffer frame(*context, sizeof(shared::SphereFrame), gpu::kBufferUsage, gpu::MemoryKind::Upload,
                    "test frame constants");
  for (ParticleLayout layout :
       {ParticleLayout::Soa8, ParticleLayout::Vec4x2, ParticleLayout::Aos, ParticleLayout::Xyz}) {
    SCOPED_TRACE(particleLayoutName(layout));
    bool perRadius = particleLayoutInfo(layout).perParticleRadius;
    const ParticleSet& set = layoutHolds(layout, perParticle) ? perParticle : global;
    ParticleUploadOptions upload;
    upload.layout = layout;
    upload.maxPartParticles = 700; // 3 parts
    upload.progress = false;
    GpuParticles particles(*context, set, upload);
    ASSERT_EQ(particles.parts().size(), 3u);
    shared::SphereFrame f{};
    f.globalRadius = particles.globalRadius();
    f.globalColor = particles.globalColor();
    std::memcpy(frame.mapped(), &f, sizeof f);
    gpu::ComputeProgram program(*context, "sphere_rt_aabbs.comp",
                                {{/* LAYOUT= */ 0, particleLayoutInfo(layout).shaderId}});
    for (const ParticlePart& part : particles.parts()) {
      gpu::Buffer boxes(*context, part.count * kSphereAabbBytes, gpu::kBufferUsage, gpu::MemoryKind::Device,
                        "test AABBs");
      context->submitAndWait([&](VkCommandBuffer cmd) {
        recordSphereAabbs(cmd, program, frame.address(), part, boxes.address());
        gpu::fullBarrier(cmd);
      });
      std::vector<float> box(part.count * 6);
      gpu::readBuffer(*context, boxes, 0, box.data(), box.size() * sizeof(float));
      for (uint64_t i = 0; i < part.count; ++i) {
        // The particle of the set at this GPU position (uploads are in spatial order).
        uint64_t g = particles.order() ? (*particles.order())[part.first + i] : part.first + i;
        const float* b = &box[6 * i];
        double r = perRadius ? double(float(set.radius[g])) : double(set.globalRadius);
        bool valid = r > 0 && std::isfinite(r);
        if (!valid) {
          EXPECT_TRUE(std::isnan(b[0])) << "particle " << g << " needs an inactive box";
          continue;
        }
        double largest = 0;
        for (int a = 0; a < 3; ++a)
          largest = std::max(largest, std::abs(double(set.xyz[3 * g + a])));
        double pad = r / 4096 + largest / 262144;
        for (int a = 0; a < 3; ++a) {
          double c = set.xyz[3 * g + a];
          ASSERT_LE(double(b[a]), c - r) << "particle " << g << " axis " << a;
          ASSERT_GE(double(b[3 + a]), c + r) << "particle " << g << " axis " << a;
          ASSERT_GE(double(b[a]), c - r - 2 * pad - 1e-6 * (std::abs(c) + r)) << "particle " << g;
          ASSERT_LE(double(b[3 + a]), c + r + 2 * pad + 1e-6 * (std::abs(c) + r)) << "particle " << g;
        }
      }
    }
  }
}

// --- Against the CPU ray caster, where the device has the extensions ---------------------------------------

namespace {

struct Variant {
  SphereMethod method;
  uint32_t meshlet = shared::kSphereMeshletLarge;
  bool taskCull = false;
};

std::string variantName(const Variant& v) {
  std::string n = sphereMethodName(v.method);
  if (v.method != SphereMethod::RayTracing)
    n += "_" + std::to_string(v.meshlet) + (v.taskCull ? "_task" : "");
  std::replace(n.begin(), n.end(), '-', '_');
  return n;
}

void PrintTo(const Variant& v, std::ostream* os) {
  *os << variantName(v);
}

class SphereMeshRtTest : public GpuTest, public ::testing::WithParamInterface<Variant> {
protected:
  void SetUp() override {
    GpuTest::SetUp();
    std::string why;
    if (!SphereRenderer::supports(*context, GetParam().method, &why)) {
      std::printf("skipped: %s\n", why.c_str());
      GTEST_SKIP() << why;
    }
    if (GetParam().taskCull && !context->features().taskShader) {
      std::printf("skipped: '%s' has no task shaders\n", context->info().name.c_str());
      GTEST_SKIP() << "no task shaders";
    }
  }
  SphereSettings settings() const {
    SphereSettings s;
    s.method = GetParam().method;
    s.meshlet = GetParam().meshlet;
    s.taskCull = GetParam().taskCull;
    return s;
  }
  std::string name(const std::string& what) const { return variantName(GetParam()) + " " + what; }
  bool points() const { return GetParam().method == SphereMethod::MeshPoints; }
};

} // namespace

TEST_P(SphereMeshRtTest, AgreesWithCpuInEveryLayout) {
  for (const GpuFrame& gpu : expectAgreementInEveryLayout(*context, name(""), settings(), 7))
    if (GetParam().method == SphereMethod::RayTracing) {
      EXPECT_GT(gpu.stats.buildMs, 0.0) << "the build is timed";
      std::printf("%s: acceleration structures built in %.3f ms, frame %.3f ms\n", name("").c_str(),
                  gpu.stats.buildMs, gpu.stats.medianMs);
    }
}

TEST_P(SphereMeshRtTest, ManyPartsAndMostSpheresOutsideTheView) {
  // Several parts (several draws, several bottom-level structures and instances, custom index = part),
  // 4 000 spheres of which most are behind the eye, beside the view or crossing the near plane: what the
  // task shader culls, the mesh shader must not need.
  std::vector<SphereSpec> spheres = randomSpheres(4000, 31, 30, 0.05, 0.5);
  ParticleSet set = makeSet(spheres);
  Camera camera = lookAt({0, 0, 0}, {1, 0.2, 0.1}, 40);
  ParticleUploadOptions upload;
  upload.maxPartParticles = 900; // 5 parts, the last one partial
  GpuFrame gpu = renderGpu(*context, set, camera, 160, 120, upload, settings());
  expectAgreement(name("many parts, most culled"), gpu, renderCpu(set, camera, 160, 120));
}

TEST_P(SphereMeshRtTest, RayTracingSplitsPartsIntoPieces) {
  // A device whose largest buffer cannot hold the build scratch of a whole part gets several bottom-level
  // structures per part (custom index = part << kSphereRtPieceBits | piece); forced here with pieces of 256:
  // 5 parts of up to 900 spheres, 4 pieces each, the last piece of every part and the last part partial.
  if (GetParam().method != SphereMethod::RayTracing) GTEST_SKIP() << "sphere-rt only";
  std::vector<SphereSpec> spheres = randomSpheres(4000, 37, 30, 0.05, 0.5);
  ParticleSet set = makeSet(spheres);
  Camera camera = lookAt({0, 0, 0}, {1, 0.2, 0.1}, 40);
  ParticleUploadOptions upload;
  upload.maxPartParticles = 900;
  SphereSettings s = settings();
  s.rtPieceParticles = 256;
  GpuFrame gpu = renderGpu(*context, set, camera, 160, 120, upload, s);
  EXPECT_EQ(gpu.stats.rtBottomLevels, 4u * 4 + 2) << "900 x 4 + 400: 4 pieces of 256 each, then 2";
  expectAgreement(name("parts in pieces of 256"), gpu, renderCpu(set, camera, 160, 120));
  s.rtPieceParticles = 1; // a structure per sphere
  upload.maxPartParticles = 0;
  std::vector<SphereSpec> few(spheres.begin(), spheres.begin() + 60);
  ParticleSet small = makeSet(few);
  gpu = renderGpu(*context, small, camera, 160, 120, upload, s);
  EXPECT_EQ(gpu.stats.rtBottomLevels, 60u);
  expectAgreement(name("pieces of one sphere"), gpu, renderCpu(small, camera, 160, 120));
  s.rtPieceParticles = 0; // as many as the device allows: one structure for the part
  gpu = renderGpu(*context, small, camera, 160, 120, upload, s);
  EXPECT_EQ(gpu.stats.rtBottomLevels, 1u);
}

TEST_P(SphereMeshRtTest, AgreesWithSphereCompute) {
  expectAgreesWithSphereCompute(*context, variantName(GetParam()), settings());
}

TEST_P(SphereMeshRtTest, SpheresAcrossTheBorderAndFrustumEdges) {
  // As in spheres_hardware_test.cpp: sphere-mesh-points, like sphere-points, may lose the parts of spheres
  // whose bounds are centered off-screen.
  expectFrustumEdges(*context, variantName(GetParam()), settings(), /* pointsMayBeLost= */ points());
}

TEST_P(SphereMeshRtTest, SphereLargerThanTheLargestPoint) {
  // sphere-mesh-points draws the sphere clipped to a square of the largest point; sphere-mesh-tris and
  // sphere-rt whole.
  expectLargestPoint(*context, variantName(GetParam()), settings(), /* clamps= */ points());
}

TEST_P(SphereMeshRtTest, CameraBillboardAndConservativeRasterization) {
  // The mesh pipelines rasterize the same impostors as the vertex pipelines, so they take the same
  // options: the camera-aligned billboard and overestimating conservative rasterization draw the same image.
  if (GetParam().method == SphereMethod::RayTracing) GTEST_SKIP() << "sphere-rt rasterizes no billboards";
  std::vector<SphereSpec> spheres = randomSpheres(2000, 41, 8, 0.1, 0.5);
  ParticleSet set = makeSet(spheres);
  Camera camera = lookAt({-9, -13, 6}, {0, 0, 0});
  SphereRaycast cpu = renderCpu(set, camera, 160, 120);
  SphereSettings s = settings();
  s.billboard = SphereBillboard::Camera;
  expectAgreement(name("camera billboard"), renderGpu(*context, set, camera, 160, 120, {}, s), cpu);
  s.billboard = SphereBillboard::Screen;
  s.conservative = true;
  std::string why;
  if (!SphereRenderer::supports(*context, s, &why)) {
    std::printf("conservative rasterization skipped: %s\n", why.c_str());
    return;
  }
  expectAgreement(name("conservative"), renderGpu(*context, set, camera, 160, 120, {}, s), cpu);
}

INSTANTIATE_TEST_SUITE_P(Spheres, SphereMeshRtTest,
                         ::testing::Values(Variant{SphereMethod::MeshPoints, 31, false},
                                           Variant{SphereMethod::MeshPoints, 15, false},
                                           Variant{SphereMethod::MeshPoints, 31, true},
                                           Variant{SphereMethod::MeshPoints, 15, true},
                                           Variant{SphereMethod::MeshTriangles, 31, false},
                                           Variant{SphereMethod::MeshTriangles, 15, false},
                                           Variant{SphereMethod::MeshTriangles, 31, true},
                                           Variant{SphereMethod::MeshTriangles, 15, true},
                                           Variant{SphereMethod::RayTracing}),
                         [](const ::testing::TestParamInfo<Variant>& param) {
                           return variantName(param.param);
                         });

} // namespace pointrast::test

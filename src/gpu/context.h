// The headless Vulkan 1.3 context: instance, chosen device, one queue that does compute, graphics and
// transfer, a command pool, and the optional validation layer. No window, no swapchain.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "gpu/vulkan_api.h"

namespace pointrast::gpu {

struct ContextOptions {
  // Device index as listed by listDevices(); nullopt = POINTRAST_DEVICE if set, else the best device
  // (discrete > integrated > virtual > CPU).
  std::optional<uint32_t> deviceIndex;
  // Khronos validation layer; nullopt = on when POINTRAST_VALIDATION=1.
  std::optional<bool> validation;
  // Print the chosen device (one line on stderr).
  bool announce = true;
  // Presenting to a window: instance extensions the window system needs (VK_KHR_surface and its platform
  // extension, as the window library lists them) and VK_KHR_swapchain on the device. UnsupportedError when
  // the loader or the device lacks them.
  std::vector<std::string> surfaceExtensions;
};

struct DeviceInfo {
  std::string name;
  std::string typeName; // "discrete GPU", "integrated GPU", "CPU (software)", ...
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  uint32_t apiVersion = 0;
  uint32_t vendorId = 0;
  std::string driver;
  bool software() const { return type == VK_PHYSICAL_DEVICE_TYPE_CPU; }
};

// Optional capabilities, queried once; methods check these and refuse with a clear sentence.
struct DeviceFeatures {
  bool float64 = false;               // shaderFloat64 (int40 depth projects in double)
  bool subgroupCompute = false;       // vote, ballot, shuffle and arithmetic in compute shaders
  bool subgroupExtendedTypes = false; // 64-bit integers in subgroup operations
  bool subgroupPartitionedNV = false; // VK_NV_shader_subgroup_partitioned
  bool geometryShader = false;        // geometry shaders (sphere-geom)
  bool largePoints = false;           // points larger than one pixel (sphere-points)
  bool vertexStores = false;          // vertexPipelineStoresAndAtomics (sphere-points counts clamped sizes)
  // VK_EXT_conservative_rasterization (overestimation; sphere pipelines' --conservative), and whether it
  // applies to point primitives too (conservativePointAndLineRasterization; sphere-points).
  bool conservativeRasterization = false;
  bool conservativePoints = false;
  // VK_EXT_mesh_shader with meshShader (sphere-mesh-points, sphere-mesh-tris), and taskShader (--task-cull).
  bool meshShader = false;
  bool taskShader = false;
  // VK_KHR_ray_tracing_pipeline + VK_KHR_acceleration_structure + VK_KHR_deferred_host_operations with
  // rayTracingPipeline and accelerationStructure (bufferDeviceAddress every device here has): sphere-rt.
  bool rayTracing = false;
};

// Whether the test hook POINTRAST_INJECT_DEVICE_LOST is set: the process's submissions, counted, are to fail
// from a given one on. Work whose number of submissions depends on the device (clock settling) stays out.
bool deviceLossInjected();
// For POINTRAST_INJECT_DEVICE_LOST=result+N: a benchmark kept a measured result; the count of submissions
// to fail starts at the first call.
void noteMeasuredResult();

class Context {
public:
  explicit Context(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queueFamily_; }
  const DeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return memory_; }
  uint32_t subgroupSize() const { return subgroupSize_; }
  const DeviceFeatures& features() const { return features_; }
  // Limits of the optional extensions, queried where the device has them (zero otherwise; pNext null).
  const VkPhysicalDeviceMeshShaderPropertiesEXT& meshShaderProperties() const { return meshProperties_; }
  const VkPhysicalDeviceRayTracingPipelinePropertiesKHR& rayTracingProperties() const {
    return rayTracingProperties_;
  }
  const VkPhysicalDeviceAccelerationStructurePropertiesKHR& accelerationStructureProperties() const {
    return accelerationProperties_;
  }
  // Largest single VkDeviceMemory allocation (VkPhysicalDeviceMaintenance3Properties), and the largest
  // buffer (maintenance4); scenes are split into parts below both.
  uint64_t maxAllocationSize() const { return maxAllocation_; }
  uint64_t maxBufferSize() const { return maxBuffer_; }
  // Sum of DEVICE_LOCAL heaps: what a scene may at most occupy.
  uint64_t deviceLocalBytes() const { return deviceLocalBytes_; }
  // Nanoseconds per timestamp tick.
  double timestampPeriodNs() const { return properties_.limits.timestampPeriod; }
  bool validationEnabled() const { return validation_; }
  bool presenting() const { return presenting_; }
  // Errors reported by the validation layer so far (tests assert this is zero).
  uint32_t validationErrors() const { return validationErrors_.load(); }

  // Records commands with `record`, submits them and waits for completion.
  void submitAndWait(const std::function<void(VkCommandBuffer)>& record) { submitAndWait(record, {}); }
  // The same, waiting for and signalling binary semaphores (a swapchain image acquired, rendering done
  // for presentation); null handles are left out.
  struct Semaphores {
    VkSemaphore wait = VK_NULL_HANDLE;
    VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    VkSemaphore signal = VK_NULL_HANDLE;
  };
  void submitAndWait(const std::function<void(VkCommandBuffer)>& record, const Semaphores& semaphores);

  // Gives a Vulkan object a name that shows in validation messages and debuggers.
  void setName(VkObjectType type, uint64_t handle, const std::string& name) const;

private:
  static VkBool32 VKAPI_PTR debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT type,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
  // Test hook: POINTRAST_INJECT_VALIDATION_ERROR=1 (with validation on) sends one error message through the
  // validation messenger as soon as it exists, so tests can show what an error reported by the layer does
  // to a command's output.
  void injectValidationError();
  void chooseDevice(const ContextOptions& options);
  void createDevice();
  void destroy();

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queueFamily_ = 0;
  VkCommandPool commandPool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  DeviceInfo info_;
  uint32_t subgroupSize_ = 0;
  DeviceFeatures features_;
  VkPhysicalDeviceMeshShaderPropertiesEXT meshProperties_{};
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rayTracingProperties_{};
  VkPhysicalDeviceAccelerationStructurePropertiesKHR accelerationProperties_{};
  uint64_t maxAllocation_ = 0;
  uint64_t maxBuffer_ = 0;
  uint64_t deviceLocalBytes_ = 0;
  bool validation_ = false;
  bool debugUtils_ = false;
  bool presenting_ = false; // VK_KHR_swapchain enabled (ContextOptions::surfaceExtensions)
  std::atomic<uint32_t> validationErrors_{0};
};

// All Vulkan devices of this machine, in enumeration order (the indices --device takes).
std::vector<DeviceInfo> listDevices();

} // namespace pointrast::gpu

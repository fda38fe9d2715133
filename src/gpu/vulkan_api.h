// Vulkan entry points, loaded at run time from libvulkan.so.1 (dlopen) rather than linked, so that a
// machine without Vulkan gets one clear sentence instead of a dynamic-linker failure, and a release
// binary needs no Vulkan at link time. Every function pointer used anywhere is listed here once.
#pragma once

#define VK_NO_PROTOTYPES
#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

// clang-format off
#define PR_VK_GLOBAL_FUNCTIONS(X) \
  X(vkCreateInstance) X(vkEnumerateInstanceExtensionProperties) X(vkEnumerateInstanceLayerProperties) \
  X(vkEnumerateInstanceVersion)

#define PR_VK_INSTANCE_FUNCTIONS(X) \
  X(vkDestroyInstance) X(vkEnumeratePhysicalDevices) X(vkGetPhysicalDeviceProperties) \
  X(vkGetPhysicalDeviceProperties2) X(vkGetPhysicalDeviceFeatures2) X(vkGetPhysicalDeviceFeatures) \
  X(vkGetPhysicalDeviceQueueFamilyProperties) X(vkGetPhysicalDeviceMemoryProperties) \
  X(vkEnumerateDeviceExtensionProperties) X(vkCreateDevice) X(vkGetDeviceProcAddr)

// From VK_EXT_debug_utils: may be null when the extension is missing.
#define PR_VK_DEBUG_FUNCTIONS(X) \
  X(vkCreateDebugUtilsMessengerEXT) X(vkDestroyDebugUtilsMessengerEXT) X(vkSetDebugUtilsObjectNameEXT)

#define PR_VK_DEVICE_FUNCTIONS(X) \
  X(vkDestroyDevice) X(vkGetDeviceQueue) X(vkDeviceWaitIdle) X(vkQueueSubmit) X(vkQueueWaitIdle) \
  X(vkCreateBuffer) X(vkDestroyBuffer) X(vkGetBufferMemoryRequirements) X(vkBindBufferMemory) \
  X(vkGetBufferDeviceAddress) X(vkAllocateMemory) X(vkFreeMemory) X(vkMapMemory) X(vkUnmapMemory) \
  X(vkInvalidateMappedMemoryRanges) \
  X(vkCreateShaderModule) X(vkDestroyShaderModule) X(vkCreatePipelineLayout) X(vkDestroyPipelineLayout) \
  X(vkCreateComputePipelines) X(vkDestroyPipeline) \
  X(vkCreateCommandPool) X(vkDestroyCommandPool) X(vkAllocateCommandBuffers) X(vkFreeCommandBuffers) \
  X(vkBeginCommandBuffer) X(vkEndCommandBuffer) X(vkResetCommandPool) \
  X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences) X(vkResetFences) \
  X(vkCreateQueryPool) X(vkDestroyQueryPool) X(vkGetQueryPoolResults) \
  X(vkCmdBindPipeline) X(vkCmdPushConstants) X(vkCmdDispatch) X(vkCmdPipelineBarrier2) \
  X(vkCmdCopyBuffer) X(vkCmdFillBuffer) X(vkCmdResetQueryPool) X(vkCmdWriteTimestamp2) \
  X(vkCreateImage) X(vkDestroyImage) X(vkGetImageMemoryRequirements) X(vkBindImageMemory) \
  X(vkCreateImageView) X(vkDestroyImageView) X(vkCreateGraphicsPipelines) X(vkCmdBeginRendering) \
  X(vkCmdEndRendering) X(vkCmdDraw) X(vkCmdSetViewport) X(vkCmdSetScissor) X(vkCmdCopyImageToBuffer)

// Of device extensions pointrast enables only where the device has them (Context and DeviceFeatures):
// VK_EXT_mesh_shader, and VK_KHR_acceleration_structure + VK_KHR_ray_tracing_pipeline. Null on a device
// without them; callers check DeviceFeatures::meshShader / rayTracing first.
#define PR_VK_MESH_FUNCTIONS(X) X(vkCmdDrawMeshTasksEXT)
#define PR_VK_RAY_TRACING_FUNCTIONS(X) \
  X(vkCreateAccelerationStructureKHR) X(vkDestroyAccelerationStructureKHR) \
  X(vkGetAccelerationStructureBuildSizesKHR) X(vkGetAccelerationStructureDeviceAddressKHR) \
  X(vkCmdBuildAccelerationStructuresKHR) X(vkCreateRayTracingPipelinesKHR) \
  X(vkGetRayTracingShaderGroupHandlesKHR) X(vkCmdTraceRaysKHR)
// Presenting to a window (the viewer): VK_KHR_surface on the instance, VK_KHR_swapchain on the device,
// enabled only when a Context is asked for them (ContextOptions); null otherwise.
#define PR_VK_SURFACE_FUNCTIONS(X) \
  X(vkDestroySurfaceKHR) X(vkGetPhysicalDeviceSurfaceSupportKHR) \
  X(vkGetPhysicalDeviceSurfaceCapabilitiesKHR) X(vkGetPhysicalDeviceSurfaceFormatsKHR) \
  X(vkGetPhysicalDeviceSurfacePresentModesKHR)
#define PR_VK_SWAPCHAIN_FUNCTIONS(X) \
  X(vkCreateSwapchainKHR) X(vkDestroySwapchainKHR) X(vkGetSwapchainImagesKHR) X(vkAcquireNextImageKHR) \
  X(vkQueuePresentKHR) X(vkCreateSemaphore) X(vkDestroySemaphore)
// clang-format on

namespace pointrast::gpu {

#define PR_VK_DECLARE(name) extern PFN_##name name;
PR_VK_GLOBAL_FUNCTIONS(PR_VK_DECLARE)
PR_VK_INSTANCE_FUNCTIONS(PR_VK_DECLARE)
PR_VK_DEBUG_FUNCTIONS(PR_VK_DECLARE)
PR_VK_DEVICE_FUNCTIONS(PR_VK_DECLARE)
PR_VK_MESH_FUNCTIONS(PR_VK_DECLARE)
PR_VK_RAY_TRACING_FUNCTIONS(PR_VK_DECLARE)
PR_VK_SURFACE_FUNCTIONS(PR_VK_DECLARE)
PR_VK_SWAPCHAIN_FUNCTIONS(PR_VK_DECLARE)
#undef PR_VK_DECLARE

// Opens libvulkan.so.1 and loads the global functions. Throws UnsupportedError naming the package to
// install when there is no loader. Idempotent.
void loadVulkanLoader();
void loadInstanceFunctions(VkInstance instance);
void loadDeviceFunctions(VkDevice device);
// The functions of the optional extensions that were enabled on `device`; the others become null (asking
// for a function of an extension that is not enabled is not allowed).
void loadExtensionDeviceFunctions(VkDevice device, bool meshShader, bool rayTracing);
// The surface functions (after an instance with VK_KHR_surface) and the swapchain functions (after a
// device with VK_KHR_swapchain).
void loadSurfaceFunctions(VkInstance instance);
void loadSwapchainFunctions(VkDevice device);
// vkGetInstanceProcAddr of the loaded libvulkan, for window libraries that create surfaces themselves.
PFN_vkGetInstanceProcAddr instanceProcAddr();

// A Vulkan call failed: which call, where, and the VkResult's name.
class VulkanError : public std::runtime_error {
public:
  VulkanError(VkResult result, const char* call, const char* file, int line);
  VkResult result() const { return result_; }

private:
  VkResult result_;
};

const char* resultName(VkResult result);

// Set once a submission did not finish in time (DeviceFault). From then on destructors leave Vulkan
// objects alone: the GPU may still be using them and waiting for it could take forever; the process
// exits soon and the driver reclaims everything.
bool deviceFaulted();
void markDeviceFaulted();

} // namespace pointrast::gpu

// Checks a VkResult in every build (benchmarks run in Release). Anything but VK_SUCCESS throws.
#define VK_CHECK(call)                                                                                       \
  do {                                                                                                       \
    VkResult pr_vk_result_ = (call);                                                                         \
    if (pr_vk_result_ != VK_SUCCESS)                                                                         \
      throw ::pointrast::gpu::VulkanError(pr_vk_result_, #call, __FILE__, __LINE__);                         \
  } while (0)

// The narrow variant for calls where some non-success codes are legal (VK_NOT_READY from a query,
// VK_TIMEOUT from a wait): returns the result when it is one of the allowed ones.
#define VK_CHECK_ALLOW(call, ...)                                                                            \
  [&]() -> VkResult {                                                                                        \
    VkResult pr_vk_result_ = (call);                                                                         \
    for (VkResult allowed : {VK_SUCCESS, __VA_ARGS__})                                                       \
      if (pr_vk_result_ == allowed) return pr_vk_result_;                                                    \
    throw ::pointrast::gpu::VulkanError(pr_vk_result_, #call, __FILE__, __LINE__);                           \
  }()

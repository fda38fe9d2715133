#include "gpu/vulkan_api.h"

#include <atomic>

#include <dlfcn.h>

#include "base/error.h"

namespace pointrast::gpu {

#define PR_VK_DEFINE(name) PFN_##name name = nullptr;
PR_VK_GLOBAL_FUNCTIONS(PR_VK_DEFINE)
PR_VK_INSTANCE_FUNCTIONS(PR_VK_DEFINE)
PR_VK_DEBUG_FUNCTIONS(PR_VK_DEFINE)
PR_VK_DEVICE_FUNCTIONS(PR_VK_DEFINE)
PR_VK_MESH_FUNCTIONS(PR_VK_DEFINE)
PR_VK_RAY_TRACING_FUNCTIONS(PR_VK_DEFINE)
PR_VK_SURFACE_FUNCTIONS(PR_VK_DEFINE)
PR_VK_SWAPCHAIN_FUNCTIONS(PR_VK_DEFINE)
#undef PR_VK_DEFINE

namespace {
PFN_vkGetInstanceProcAddr getInstanceProcAddr = nullptr;
}

void loadVulkanLoader() {
  if (getInstanceProcAddr) return;
  void* library = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
  if (!library) library = dlopen("libvulkan.so", RTLD_NOW | RTLD_LOCAL);
  if (!library)
    throw UnsupportedError("Vulkan is not installed (libvulkan.so.1 not found): install the loader and a "
                           "driver, e.g. `apt-get install libvulkan1 mesa-vulkan-drivers`");
  getInstanceProcAddr = reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(library, "vkGetInstanceProcAddr"));
  if (!getInstanceProcAddr) throw UnsupportedError("libvulkan.so.1 has no vkGetInstanceProcAddr");
#define PR_VK_LOAD(name)                                                                                     \
  name = reinterpret_cast<PFN_##name>(getInstanceProcAddr(VK_NULL_HANDLE, #name));                           \
  if (!name) throw UnsupportedError("the Vulkan loader lacks " #name " (Vulkan 1.3 is required)");
  PR_VK_GLOBAL_FUNCTIONS(PR_VK_LOAD)
#undef PR_VK_LOAD
}

void loadInstanceFunctions(VkInstance instance) {
#define PR_VK_LOAD(name)                                                                                     \
  name = reinterpret_cast<PFN_##name>(getInstanceProcAddr(instance, #name));                                 \
  if (!name) throw UnsupportedError("the Vulkan loader lacks " #name " (Vulkan 1.3 is required)");
  PR_VK_INSTANCE_FUNCTIONS(PR_VK_LOAD)
#undef PR_VK_LOAD
#define PR_VK_LOAD_OPTIONAL(name) name = reinterpret_cast<PFN_##name>(getInstanceProcAddr(instance, #name));
  PR_VK_DEBUG_FUNCTIONS(PR_VK_LOAD_OPTIONAL)
#undef PR_VK_LOAD_OPTIONAL
}

void loadDeviceFunctions(VkDevice device) {
#define PR_VK_LOAD(name)                                                                                     \
  name = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(device, #name));                                   \
  if (!name) throw UnsupportedError("the Vulkan driver lacks " #name " (Vulkan 1.3 is required)");
  PR_VK_DEVICE_FUNCTIONS(PR_VK_LOAD)
#undef PR_VK_LOAD
}

void loadExtensionDeviceFunctions(VkDevice device, bool meshShader, bool rayTracing) {
#define PR_VK_LOAD(name)                                                                                     \
  name = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(device, #name));                                   \
  if (!name) throw UnsupportedError("the Vulkan driver lacks " #name ", although it lists its extension");
#define PR_VK_CLEAR(name) name = nullptr;
  if (meshShader) {
    PR_VK_MESH_FUNCTIONS(PR_VK_LOAD)
  } else {
    PR_VK_MESH_FUNCTIONS(PR_VK_CLEAR)
  }
  if (rayTracing) {
    PR_VK_RAY_TRACING_FUNCTIONS(PR_VK_LOAD)
  } else {
    PR_VK_RAY_TRACING_FUNCTIONS(PR_VK_CLEAR)
  }
#undef PR_VK_CLEAR
#undef PR_VK_LOAD
}

void loadSurfaceFunctions(VkInstance instance) {
#define PR_VK_LOAD(name)                                                                                     \
  name = reinterpret_cast<PFN_##name>(getInstanceProcAddr(instance, #name));                                 \
  if (!name) throw UnsupportedError("the Vulkan loader lacks " #name ", although VK_KHR_surface is "         \
                                                                     "enabled");
  PR_VK_SURFACE_FUNCTIONS(PR_VK_LOAD)
#undef PR_VK_LOAD
}

void loadSwapchainFunctions(VkDevice device) {
#define PR_VK_LOAD(name)                                                                                     \
  name = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(device, #name));                                   \
  if (!name)                                                                                                 \
    throw UnsupportedError("the Vulkan driver lacks " #name ", although VK_KHR_swapchain is enabled");
  PR_VK_SWAPCHAIN_FUNCTIONS(PR_VK_LOAD)
#undef PR_VK_LOAD
}

PFN_vkGetInstanceProcAddr instanceProcAddr() {
  return getInstanceProcAddr;
}

namespace {
std::atomic<bool> gDeviceFaulted{false};
}

bool deviceFaulted() {
  return gDeviceFaulted.load();
}
void markDeviceFaulted() {
  gDeviceFaulted = true;
}

const char* resultName(VkResult result) {
  switch (result) {
#define PR_CASE(r)                                                                                           \
  case r:                                                                                                    \
    return #r;
    PR_CASE(VK_SUCCESS)
    PR_CASE(VK_NOT_READY)
    PR_CASE(VK_TIMEOUT)
    PR_CASE(VK_INCOMPLETE)
    PR_CASE(VK_ERROR_OUT_OF_HOST_MEMORY) PR_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        PR_CASE(VK_ERROR_INITIALIZATION_FAILED) PR_CASE(VK_ERROR_DEVICE_LOST)
            PR_CASE(VK_ERROR_MEMORY_MAP_FAILED) PR_CASE(VK_ERROR_LAYER_NOT_PRESENT)
                PR_CASE(VK_ERROR_EXTENSION_NOT_PRESENT) PR_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
                    PR_CASE(VK_ERROR_INCOMPATIBLE_DRIVER) PR_CASE(VK_ERROR_TOO_MANY_OBJECTS)
                        PR_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED) PR_CASE(VK_ERROR_UNKNOWN)
                            PR_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
#undef PR_CASE
                                default : return "VkResult(?)";
  }
}

VulkanError::VulkanError(VkResult result, const char* call, const char* file, int line)
    : std::runtime_error(std::string("Vulkan call failed with ") + resultName(result) + ": " + call + " (" +
                         file + ":" + std::to_string(line) + ")"),
      result_(result) {}

} // namespace pointrast::gpu

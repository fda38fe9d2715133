#include "gpu/context.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "base/error.h"
#include "gpu/device_rank.h"

namespace pointrast::gpu {

namespace {

// Generous for software Vulkan on two cores and for 4-billion-point frames; short enough that a hang is
// reported within a benchmark's time budget. POINTRAST_GPU_TIMEOUT_S overrides it (tests use a tiny one).
double submitTimeoutSeconds() {
  if (const char* env = std::getenv("POINTRAST_GPU_TIMEOUT_S"); env && *env) {
    char* end = nullptr;
    double v = std::strtod(env, &end);
    if (*end == '\0' && v > 0) return v;
  }
  return 120.0;
}

// Test hook: POINTRAST_INJECT_DEVICE_LOST=N makes the Nth submission of the process (counting from 1) and
// every later one fail with VK_ERROR_DEVICE_LOST instead of reaching the driver, so tests can show what a
// lost device leaves behind (a benchmark's reports, one line from the CLI). With result+N the count starts
// at the first measured result a benchmark keeps (noteMeasuredResult): where reader threads also submit
// (node uploads), a count from the start lands at a point that depends on their timing.
struct InjectedLoss {
  uint64_t from = 0;
  bool afterResult = false;
};

InjectedLoss injectedLoss() {
  static const InjectedLoss loss = [] {
    InjectedLoss l;
    const char* env = std::getenv("POINTRAST_INJECT_DEVICE_LOST");
    if (!env || !*env) return l;
    std::string_view v(env);
    if (v.starts_with("result+")) {
      l.afterResult = true;
      v.remove_prefix(7);
    }
    l.from = std::strtoull(std::string(v).c_str(), nullptr, 10);
    return l;
  }();
  return loss;
}

std::atomic<bool> measuredResultNoted{false};

bool injectedDeviceLoss() {
  static std::atomic<uint64_t> submissions{0};
  const InjectedLoss loss = injectedLoss();
  if (loss.from == 0 || (loss.afterResult && !measuredResultNoted)) return false;
  return ++submissions >= loss.from;
}

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool envFlag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0;
}

const char* typeName(VkPhysicalDeviceType type) {
  switch (type) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
    return "discrete GPU";
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
    return "integrated GPU";
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
    return "virtual GPU";
  case VK_PHYSICAL_DEVICE_TYPE_CPU:
    return "CPU (software Vulkan)";
  default:
    return "other";
  }
}


DeviceInfo describe(VkPhysicalDevice physical) {
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver};
  vkGetPhysicalDeviceProperties2(physical, &props);
  DeviceInfo info;
  info.name = props.properties.deviceName;
  info.type = props.properties.deviceType;
  info.typeName = typeName(info.type);
  info.apiVersion = props.properties.apiVersion;
  info.vendorId = props.properties.vendorID;
  info.driver = std::string(driver.driverName) + " " + driver.driverInfo;
  return info;
}

struct Instance {
  VkInstance handle = VK_NULL_HANDLE;
  bool debugUtils = false;
};

Instance createInstance(bool validation, const std::vector<std::string>& surfaceExtensions = {}) {
  loadVulkanLoader();
  uint32_t version = 0;
  VK_CHECK(vkEnumerateInstanceVersion(&version));
  if (version < VK_API_VERSION_1_3)
    throw UnsupportedError("the Vulkan loader is older than 1.3; install a newer libvulkan1");

  uint32_t count = 0;
  VK_CHECK(vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr));
  std::vector<VkExtensionProperties> available(count);
  VK_CHECK(vkEnumerateInstanceExtensionProperties(nullptr, &count, available.data()));
  std::vector<const char*> extensions;
  Instance result;
  for (const auto& e : available)
    if (std::strcmp(e.extensionName, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) == 0) result.debugUtils = true;
  if (result.debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  for (const std::string& wanted : surfaceExtensions) {
    bool found = std::any_of(available.begin(), available.end(),
                             [&](const VkExtensionProperties& e) { return wanted == e.extensionName; });
    if (!found)
      throw UnsupportedError("the Vulkan loader lacks " + wanted + ", which showing a window needs");
    extensions.push_back(wanted.c_str());
  }

  std::vector<const char*> layers;
  if (validation) {
    VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
    std::vector<VkLayerProperties> available_layers(count);
    VK_CHECK(vkEnumerateInstanceLayerProperties(&count, available_layers.data()));
    bool found =
        std::any_of(available_layers.begin(), available_layers.end(), [](const VkLayerProperties& l) {
          return std::strcmp(l.layerName, kValidationLayer) == 0;
        });
    if (!found)
      throw UnsupportedError("POINTRAST_VALIDATION is set but the Khronos validation layer is not installed "
                             "(`apt-get install vulkan-validationlayers`)");
    layers.push_back(kValidationLayer);
  }

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "pointrast";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo create{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  create.pApplicationInfo = &app;
  create.enabledExtensionCount = uint32_t(extensions.size());
  create.ppEnabledExtensionNames = extensions.data();
  create.enabledLayerCount = uint32_t(layers.size());
  create.ppEnabledLayerNames = layers.data();
  VkResult r = vkCreateInstance(&create, nullptr, &result.handle);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED)
    throw UnsupportedError("no Vulkan driver found: install one, e.g. `apt-get install mesa-vulkan-drivers` "
                           "for software rendering, or your GPU vendor's driver");
  VK_CHECK(r);
  loadInstanceFunctions(result.handle);
  if (!surfaceExtensions.empty()) loadSurfaceFunctions(result.handle);
  return result;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
  uint32_t count = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  return devices;
}

} // namespace

bool deviceLossInjected() {
  return injectedLoss().from > 0;
}

void noteMeasuredResult() {
  measuredResultNoted = true;
}

std::vector<DeviceInfo> listDevices() {
  Instance instance = createInstance(false);
  std::vector<DeviceInfo> result;
  for (VkPhysicalDevice d : physicalDevices(instance.handle))
    result.push_back(describe(d));
  vkDestroyInstance(instance.handle, nullptr);
  return result;
}

Context::Context(const ContextOptions& options) {
  validation_ = options.validation.value_or(envFlag("POINTRAST_VALIDATION"));
  presenting_ = !options.surfaceExtensions.empty();
  Instance instance = createInstance(validation_, options.surfaceExtensions);
  instance_ = instance.handle;
  debugUtils_ = instance.debugUtils && vkCreateDebugUtilsMessengerEXT && vkSetDebugUtilsObjectNameEXT;
  try {
    if (debugUtils_ && validation_) {
      VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
      info.messageSeverity =
          VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
      info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
      info.pfnUserCallback = &Context::debugCallback;
      info.pUserData = this;
      VK_CHECK(vkCreateDebugUtilsMessengerEXT(instance_, &info, nullptr, &messenger_));
      if (envFlag("POINTRAST_INJECT_VALIDATION_ERROR")) injectValidationError();
    }
    chooseDevice(options);
    createDevice();
  } catch (...) {
    destroy();
    throw;
  }
  if (options.announce) {
    std::fprintf(stderr, "device: %s (%s, %s)%s\n", info_.name.c_str(), info_.typeName.c_str(),
                 info_.driver.c_str(), validation_ ? ", validation on" : "");
    if (info_.software())
      std::fprintf(stderr, "note: no GPU found; rendering on the CPU with software Vulkan (lavapipe), "
                           "which is correct but slow\n");
  }
}

Context::~Context() {
  destroy();
}

void Context::destroy() {
  if (deviceFaulted()) return; // see markDeviceFaulted()
  if (device_) {
    vkDeviceWaitIdle(device_);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (commandPool_) vkDestroyCommandPool(device_, commandPool_, nullptr);
    vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
  if (messenger_) vkDestroyDebugUtilsMessengerEXT(instance_, messenger_, nullptr);
  messenger_ = VK_NULL_HANDLE;
  if (instance_) vkDestroyInstance(instance_, nullptr);
  instance_ = VK_NULL_HANDLE;
}

void Context::injectValidationError() {
  VkDebugUtilsMessengerCallbackDataEXT data{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT};
  data.pMessageIdName = "pointrast-injected";
  data.pMessage = "an error injected by POINTRAST_INJECT_VALIDATION_ERROR (a test of what follows one)";
  if (vkSubmitDebugUtilsMessageEXT)
    vkSubmitDebugUtilsMessageEXT(instance_, VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
                                 VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT, &data);
}

VkBool32 VKAPI_PTR Context::debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<Context*>(user);
  bool error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  if (error) self->validationErrors_++;
  std::fprintf(stderr, "validation %s: %s\n", error ? "error" : "warning", data->pMessage);
  return VK_FALSE;
}

void Context::chooseDevice(const ContextOptions& options) {
  std::vector<VkPhysicalDevice> devices = physicalDevices(instance_);
  if (devices.empty())
    throw UnsupportedError("no Vulkan device found: install a driver, e.g. `apt-get install "
                           "mesa-vulkan-drivers` for software rendering");
  std::optional<uint32_t> index = options.deviceIndex;
  if (!index) {
    if (const char* env = std::getenv("POINTRAST_DEVICE"); env && *env) {
      char* end = nullptr;
      unsigned long v = std::strtoul(env, &end, 10);
      if (*end != '\0') throw InputError(std::string("POINTRAST_DEVICE='") + env + "' is not a device index");
      index = uint32_t(v);
    }
  }
  if (index) {
    if (*index >= devices.size())
      throw InputError("device " + std::to_string(*index) + " does not exist; this machine has " +
                       std::to_string(devices.size()) + " Vulkan device(s), numbered from 0");
    physical_ = devices[*index];
  } else {
    physical_ = *std::max_element(devices.begin(), devices.end(), [](VkPhysicalDevice a, VkPhysicalDevice b) {
      return deviceTypeRank(describe(a).type) < deviceTypeRank(describe(b).type);
    });
  }
  info_ = describe(physical_);
  if (info_.apiVersion < VK_API_VERSION_1_3)
    throw UnsupportedError("device '" + info_.name + "' supports only Vulkan " +
                           std::to_string(VK_API_VERSION_MAJOR(info_.apiVersion)) + "." +
                           std::to_string(VK_API_VERSION_MINOR(info_.apiVersion)) + "; pointrast needs 1.3");
}

namespace {

// The feature structures the device reports (has*) and those given to vkCreateDevice (want*), linked
// by pNext; the chains point into the object, so it stays where it was made.
struct FeatureChain {
  VkPhysicalDeviceVulkan13Features has13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceVulkan12Features has12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &has13};
  VkPhysicalDeviceFeatures2 has{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &has12};
  VkPhysicalDeviceVulkan13Features want13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceVulkan12Features want12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &want13};
  VkPhysicalDeviceFeatures2 want{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &want12};
  VkPhysicalDeviceMeshShaderFeaturesEXT wantMesh{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR wantAccel{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR wantRayTracing{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};

  FeatureChain() = default;
  FeatureChain(const FeatureChain&) = delete;
  FeatureChain& operator=(const FeatureChain&) = delete;
  // Adds a structure of an extension to what vkCreateDevice is given.
  template <class T> void enable(T& feature) {
    feature.pNext = want13.pNext;
    want13.pNext = &feature;
  }
};

// Throws UnsupportedError unless the device has what every method needs; then asks for that and for the
// optional core features the device has (methods check DeviceFeatures before they use one).
void chooseCoreFeatures(FeatureChain& c, const std::string& deviceName) {
  auto require = [&](VkBool32 present, const char* feature) {
    if (!present)
      throw UnsupportedError("device '" + deviceName + "' lacks " + feature +
                             ", which every pointrast method needs");
  };
  require(c.has.features.shaderInt64, "shaderInt64");
  require(c.has12.bufferDeviceAddress, "bufferDeviceAddress");
  require(c.has12.shaderBufferInt64Atomics, "shaderBufferInt64Atomics (64-bit atomics on buffers)");
  require(c.has13.synchronization2, "synchronization2");
  c.want13.synchronization2 = VK_TRUE;
  c.want13.dynamicRendering = c.has13.dynamicRendering; // hw-points draws without render pass objects
  c.want13.maintenance4 = c.has13.maintenance4;
  c.want13.subgroupSizeControl = c.has13.subgroupSizeControl;
  c.want13.computeFullSubgroups = c.has13.computeFullSubgroups;
  c.want12.bufferDeviceAddress = VK_TRUE;
  c.want12.shaderBufferInt64Atomics = VK_TRUE;
  c.want12.shaderSharedInt64Atomics = c.has12.shaderSharedInt64Atomics;
  c.want12.scalarBlockLayout = c.has12.scalarBlockLayout;
  c.want12.hostQueryReset = c.has12.hostQueryReset;
  c.want12.shaderSubgroupExtendedTypes = c.has12.shaderSubgroupExtendedTypes;
  c.want.features.shaderInt64 = VK_TRUE;
  c.want.features.shaderFloat64 = c.has.features.shaderFloat64;
  c.want.features.vertexPipelineStoresAndAtomics = c.has.features.vertexPipelineStoresAndAtomics;
  c.want.features.fragmentStoresAndAtomics = c.has.features.fragmentStoresAndAtomics;
  c.want.features.largePoints = c.has.features.largePoints;
  c.want.features.geometryShader = c.has.features.geometryShader;
}

// The first queue family with graphics, compute and timestamps.
uint32_t chooseQueueFamily(VkPhysicalDevice physical, const std::string& deviceName) {
  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &familyCount, families.data());
  constexpr VkQueueFlags kWanted = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
  for (uint32_t f = 0; f < familyCount; ++f)
    if ((families[f].queueFlags & kWanted) == kWanted && families[f].timestampValidBits > 0) return f;
  throw UnsupportedError("device '" + deviceName + "' has no queue with graphics, compute and timestamps");
}

// The device's extensions, by name.
class ExtensionSet {
public:
  explicit ExtensionSet(VkPhysicalDevice physical) {
    uint32_t count = 0;
    VK_CHECK(vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, nullptr));
    all_.resize(count);
    VK_CHECK(vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, all_.data()));
  }
  bool has(const char* name) const {
    return std::any_of(all_.begin(), all_.end(), [&](const VkExtensionProperties& e) {
      return std::strcmp(e.extensionName, name) == 0;
    });
  }

private:
  std::vector<VkExtensionProperties> all_;
};

// Mesh shaders and ray tracing: features and limits are queried only where the device lists the
// extensions (a structure of an unsupported extension in a query or in vkCreateDevice is invalid), and
// enabled only where the features are present. VK_KHR_spirv_1_4, which both require, is core in 1.2.
// Fills `features`' meshShader, taskShader and rayTracing and the extensions' properties (zero where not
// enabled).
void enableMeshAndRayTracing(VkPhysicalDevice physical, const ExtensionSet& extensions, FeatureChain& chain,
                             std::vector<const char*>& enabled, DeviceFeatures& features,
                             VkPhysicalDeviceMeshShaderPropertiesEXT& meshProperties,
                             VkPhysicalDeviceRayTracingPipelinePropertiesKHR& rayTracingProperties,
                             VkPhysicalDeviceAccelerationStructurePropertiesKHR& accelerationProperties) {
  VkPhysicalDeviceMeshShaderFeaturesEXT hasMesh{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR hasAccel{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR hasRayTracing{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  const bool meshExtension = extensions.has(VK_EXT_MESH_SHADER_EXTENSION_NAME);
  const bool rayTracingExtensions = extensions.has(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME) &&
                                    extensions.has(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME) &&
                                    extensions.has(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
  if (meshExtension || rayTracingExtensions) {
    VkPhysicalDeviceFeatures2 extensionFeatures{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    VkPhysicalDeviceProperties2 extensionProperties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    meshProperties = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_PROPERTIES_EXT};
    rayTracingProperties = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
    accelerationProperties = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
    if (meshExtension) {
      hasMesh.pNext = extensionFeatures.pNext;
      extensionFeatures.pNext = &hasMesh;
      meshProperties.pNext = extensionProperties.pNext;
      extensionProperties.pNext = &meshProperties;
    }
    if (rayTracingExtensions) {
      hasAccel.pNext = extensionFeatures.pNext;
      hasRayTracing.pNext = &hasAccel;
      extensionFeatures.pNext = &hasRayTracing;
      accelerationProperties.pNext = extensionProperties.pNext;
      rayTracingProperties.pNext = &accelerationProperties;
      extensionProperties.pNext = &rayTracingProperties;
    }
    vkGetPhysicalDeviceFeatures2(physical, &extensionFeatures);
    vkGetPhysicalDeviceProperties2(physical, &extensionProperties);
    meshProperties.pNext = nullptr;
    rayTracingProperties.pNext = nullptr;
    accelerationProperties.pNext = nullptr;
  }
  if (meshExtension && hasMesh.meshShader) {
    enabled.push_back(VK_EXT_MESH_SHADER_EXTENSION_NAME);
    chain.wantMesh.meshShader = VK_TRUE;
    chain.wantMesh.taskShader = hasMesh.taskShader;
    chain.enable(chain.wantMesh);
    features.meshShader = true;
    features.taskShader = hasMesh.taskShader;
  } else {
    meshProperties = {};
  }
  if (rayTracingExtensions && hasRayTracing.rayTracingPipeline && hasAccel.accelerationStructure) {
    enabled.push_back(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
    enabled.push_back(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
    enabled.push_back(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
    chain.wantAccel.accelerationStructure = VK_TRUE;
    chain.wantRayTracing.rayTracingPipeline = VK_TRUE;
    chain.enable(chain.wantAccel);
    chain.enable(chain.wantRayTracing);
    features.rayTracing = true;
  } else {
    rayTracingProperties = {};
    accelerationProperties = {};
  }
}

} // namespace

void Context::createDevice() {
  VkPhysicalDeviceMaintenance4Properties m4{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_PROPERTIES};
  VkPhysicalDeviceMaintenance3Properties m3{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES, &m4};
  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES, &m3};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &subgroup};
  vkGetPhysicalDeviceProperties2(physical_, &props);
  properties_ = props.properties;
  subgroupSize_ = subgroup.subgroupSize;
  constexpr VkSubgroupFeatureFlags kComputeOps =
      VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_VOTE_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT |
      VK_SUBGROUP_FEATURE_SHUFFLE_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_RELATIVE_BIT |
      VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
  features_.subgroupCompute = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                              (subgroup.supportedOperations & kComputeOps) == kComputeOps;
  maxAllocation_ = m3.maxMemoryAllocationSize;
  maxBuffer_ = m4.maxBufferSize;
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
  for (uint32_t h = 0; h < memory_.memoryHeapCount; ++h)
    if (memory_.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      deviceLocalBytes_ += memory_.memoryHeaps[h].size;
  const bool partitioned = subgroup.supportedOperations & VK_SUBGROUP_FEATURE_PARTITIONED_BIT_NV;

  FeatureChain chain;
  vkGetPhysicalDeviceFeatures2(physical_, &chain.has);
  chooseCoreFeatures(chain, info_.name);
  features_.float64 = chain.has.features.shaderFloat64;
  features_.subgroupExtendedTypes = chain.has12.shaderSubgroupExtendedTypes;
  features_.geometryShader = chain.has.features.geometryShader;
  features_.largePoints = chain.has.features.largePoints;
  features_.vertexStores = chain.has.features.vertexPipelineStoresAndAtomics;
  queueFamily_ = chooseQueueFamily(physical_, info_.name);

  const ExtensionSet extensions(physical_);
  std::vector<const char*> enabled;
  if (extensions.has(VK_EXT_CONSERVATIVE_RASTERIZATION_EXTENSION_NAME)) {
    VkPhysicalDeviceConservativeRasterizationPropertiesEXT conservative{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_CONSERVATIVE_RASTERIZATION_PROPERTIES_EXT};
    VkPhysicalDeviceProperties2 conservativeProps{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2,
                                                  &conservative};
    vkGetPhysicalDeviceProperties2(physical_, &conservativeProps);
    enabled.push_back(VK_EXT_CONSERVATIVE_RASTERIZATION_EXTENSION_NAME);
    features_.conservativeRasterization = true;
    features_.conservativePoints = conservative.conservativePointAndLineRasterization;
  }
  enableMeshAndRayTracing(physical_, extensions, chain, enabled, features_, meshProperties_,
                          rayTracingProperties_, accelerationProperties_);
  if (presenting_) {
    if (!extensions.has(VK_KHR_SWAPCHAIN_EXTENSION_NAME))
      throw UnsupportedError("device '" + info_.name + "' cannot present to a window (no VK_KHR_swapchain)");
    enabled.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  }
  if (partitioned && extensions.has(VK_NV_SHADER_SUBGROUP_PARTITIONED_EXTENSION_NAME)) {
    enabled.push_back(VK_NV_SHADER_SUBGROUP_PARTITIONED_EXTENSION_NAME);
    features_.subgroupPartitionedNV = true;
  }

  float priority = 1.0f;
  VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queueInfo.queueFamilyIndex = queueFamily_;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;
  VkDeviceCreateInfo create{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &chain.want};
  create.enabledExtensionCount = uint32_t(enabled.size());
  create.ppEnabledExtensionNames = enabled.data();
  create.queueCreateInfoCount = 1;
  create.pQueueCreateInfos = &queueInfo;
  VK_CHECK(vkCreateDevice(physical_, &create, nullptr, &device_));
  loadDeviceFunctions(device_);
  loadExtensionDeviceFunctions(device_, features_.meshShader, features_.rayTracing);
  if (presenting_) loadSwapchainFunctions(device_);
  vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

  VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  poolInfo.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  poolInfo.queueFamilyIndex = queueFamily_;
  VK_CHECK(vkCreateCommandPool(device_, &poolInfo, nullptr, &commandPool_));
  VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_CHECK(vkCreateFence(device_, &fenceInfo, nullptr, &fence_));
  setName(VK_OBJECT_TYPE_QUEUE, uint64_t(queue_), "main queue");
  setName(VK_OBJECT_TYPE_COMMAND_POOL, uint64_t(commandPool_), "main command pool");
}

void Context::setName(VkObjectType type, uint64_t handle, const std::string& name) const {
  if (!debugUtils_) return;
  VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name.c_str();
  VK_CHECK(vkSetDebugUtilsObjectNameEXT(device_, &info));
}

void Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record,
                            const Semaphores& semaphores) {
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = commandPool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VK_CHECK(vkAllocateCommandBuffers(device_, &alloc, &cmd));
  struct Free {
    VkDevice device;
    VkCommandPool pool;
    VkCommandBuffer cmd;
    ~Free() {
      if (cmd) vkFreeCommandBuffers(device, pool, 1, &cmd);
    }
  } freeLater{device_, commandPool_, cmd};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
  record(cmd);
  VK_CHECK(vkEndCommandBuffer(cmd));
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  if (semaphores.wait) {
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &semaphores.wait;
    submit.pWaitDstStageMask = &semaphores.waitStage;
  }
  if (semaphores.signal) {
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &semaphores.signal;
  }
  VK_CHECK(vkResetFences(device_, 1, &fence_));
  // A lost device throws DeviceFault, exhausted memory UnsupportedError (nothing was submitted then).
  const VkResult submitted =
      injectedDeviceLoss() ? VK_ERROR_DEVICE_LOST : vkQueueSubmit(queue_, 1, &submit, fence_);
  if (submitted != VK_SUCCESS) throwVulkanFailure(submitted, "vkQueueSubmit", __FILE__, __LINE__);
  // Never hang: work that has not finished after submitTimeoutSeconds() is a GPU fault (or a shader that
  // never ends), reported as one clear error instead of a process that waits forever.
  const double limit = submitTimeoutSeconds();
  const VkResult waited = vkWaitForFences(device_, 1, &fence_, VK_TRUE, uint64_t(limit * 1e9));
  if (waited == VK_SUCCESS) return;
  // Timed out, or the wait failed (device lost, out of memory): the command buffer may still execute, so
  // it stays allocated until the pool goes with the context, and the device counts as faulted.
  freeLater.cmd = VK_NULL_HANDLE;
  markDeviceFaulted();
  if (waited != VK_TIMEOUT)
    throw DeviceFault("the GPU failed while running a submission on '" + info_.name + "' (" +
                      resultName(waited) + " from vkWaitForFences); nothing more can run on it");
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", limit);
  throw DeviceFault("the GPU did not finish a submission within " + std::string(seconds) + " s on '" +
                    info_.name + "' (a hung shader or a device fault)");
}

} // namespace pointrast::gpu

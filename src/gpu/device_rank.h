// How much a front end prefers a device type when none is named: discrete > integrated > virtual > CPU >
// other. gpu::Context's own choice and the choice of a rank's device under mpirun (app/distributed) agree.
#pragma once

#include <vulkan/vulkan.h>

namespace pointrast::gpu {

inline int deviceTypeRank(VkPhysicalDeviceType type) {
  switch (type) {
  case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
    return 4;
  case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
    return 3;
  case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
    return 2;
  case VK_PHYSICAL_DEVICE_TYPE_CPU:
    return 1;
  default:
    return 0;
  }
}

} // namespace pointrast::gpu

// GLFW entry points, loaded at run time from libglfw.so.3 (dlopen) rather than linked, as Vulkan is
// (gpu/vulkan_api.h): a pointrast binary then starts on a server without X11 or GLFW, where `render` and
// `render --path` work, and only `view` asks for the library. Every function used is listed here once.
#pragma once

#include "gpu/vulkan_api.h" // before glfw3.h, which declares glfwCreateWindowSurface with Vulkan's types

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

// clang-format off
#define PR_GLFW_FUNCTIONS(X) \
  X(glfwInit) X(glfwTerminate) X(glfwSetErrorCallback) X(glfwWindowHint) X(glfwCreateWindow) \
  X(glfwDestroyWindow) X(glfwWindowShouldClose) X(glfwSetWindowShouldClose) X(glfwPollEvents) \
  X(glfwWaitEventsTimeout) X(glfwGetFramebufferSize) X(glfwGetWindowSize) X(glfwSetWindowUserPointer) \
  X(glfwGetWindowUserPointer) X(glfwSetCursorPosCallback) X(glfwSetMouseButtonCallback) \
  X(glfwSetScrollCallback) X(glfwSetKeyCallback) X(glfwSetCharCallback) X(glfwSetFramebufferSizeCallback) \
  X(glfwSetWindowRefreshCallback) X(glfwGetCursorPos) X(glfwGetTime) X(glfwVulkanSupported) \
  X(glfwGetRequiredInstanceExtensions) X(glfwCreateWindowSurface) X(glfwSetWindowTitle) X(glfwGetKey)
// clang-format on

namespace pointrast::view::glfw {

#define PR_GLFW_DECLARE(name) extern decltype(&::name) name;
PR_GLFW_FUNCTIONS(PR_GLFW_DECLARE)
#undef PR_GLFW_DECLARE

// Opens libglfw.so.3 and loads every function. Throws UnsupportedError naming the package when the
// library is missing. Idempotent.
void load();

} // namespace pointrast::view::glfw

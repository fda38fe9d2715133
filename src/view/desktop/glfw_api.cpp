#include "view/desktop/glfw_api.h"

#include <dlfcn.h>

#include "base/error.h"

namespace pointrast::view::glfw {

#define PR_GLFW_DEFINE(name) decltype(&::name) name = nullptr;
PR_GLFW_FUNCTIONS(PR_GLFW_DEFINE)
#undef PR_GLFW_DEFINE

void load() {
  static void* library = nullptr;
  if (library) return;
  void* opened = dlopen("libglfw.so.3", RTLD_NOW | RTLD_LOCAL);
  if (!opened)
    throw UnsupportedError(
        "the desktop viewer needs GLFW (libglfw.so.3 not found): `apt-get install libglfw3`");
#define PR_GLFW_LOAD(name)                                                                                   \
  name = reinterpret_cast<decltype(&::name)>(dlsym(opened, #name));                                          \
  if (!name) throw UnsupportedError("libglfw.so.3 lacks " #name " (GLFW 3.3 or newer is needed)");
  PR_GLFW_FUNCTIONS(PR_GLFW_LOAD)
#undef PR_GLFW_LOAD
  library = opened;
}

} // namespace pointrast::view::glfw

#include "view/web/civetweb_api.h"

#include <dlfcn.h>

#include <filesystem>
#include <system_error>

#include "base/error.h"

namespace pointrast::view::civetweb {

#define PR_CIVETWEB_DEFINE(name) decltype(&::name) name = nullptr;
PR_CIVETWEB_FUNCTIONS(PR_CIVETWEB_DEFINE)
#undef PR_CIVETWEB_DEFINE

namespace {

constexpr const char* kLibrary = "libcivetweb.so.1";

void* open() {
  if (void* library = dlopen(kLibrary, RTLD_NOW | RTLD_LOCAL)) return library;
  std::error_code error;
  std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error) return nullptr;
  return dlopen((self.parent_path() / kLibrary).c_str(), RTLD_NOW | RTLD_LOCAL);
}

} // namespace

void load() {
  static void* library = nullptr;
  if (library) return;
  void* opened = open();
  if (!opened)
    throw UnsupportedError(
        "the browser viewer needs civetweb (libcivetweb.so.1 not found): `apt-get install libcivetweb1`");
#define PR_CIVETWEB_LOAD(name)                                                                               \
  name = reinterpret_cast<decltype(&::name)>(dlsym(opened, #name));                                          \
  if (!name) throw UnsupportedError("libcivetweb.so.1 lacks " #name " (civetweb 1.15 or newer is needed)");
  PR_CIVETWEB_FUNCTIONS(PR_CIVETWEB_LOAD)
#undef PR_CIVETWEB_LOAD
  if (!mg_check_feature(MG_FEATURES_WEBSOCKET))
    throw UnsupportedError("this libcivetweb.so.1 was built without WebSocket support");
  library = opened;
}

} // namespace pointrast::view::civetweb

#include "gpu/shader_registry.h"

#include <cassert>
#include <cstdio>
#include <cstdlib>

namespace pointrast::gpu {

std::span<const uint32_t> findShader(std::string_view name) {
  for (const EmbeddedShader& s : embeddedShaders())
    if (s.name == name) return s.words;
  // A missing embedded shader is a build mistake, never a user error.
  std::fprintf(stderr, "internal error: shader '%.*s' is not embedded in this build\n", int(name.size()),
               name.data());
  std::abort();
}

} // namespace pointrast::gpu

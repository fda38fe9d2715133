#include "io/octree_source.h"

#include "base/error.h"
#include "io/potree.h"

namespace pointrast::io {

bool looksLikeOctree(const std::filesystem::path& path) {
  return looksLikePotree(path);
}

std::unique_ptr<lod::NodeSource> openOctree(const std::filesystem::path& path) {
  if (looksLikePotree(path)) return openPotree(path);
  throw InputError(path.string() +
                   " is not an octree: the LOD methods draw Potree 2.0 folders (build one with "
                   "`pointrast lod " +
                   path.filename().string() + " -o DIR`)");
}

} // namespace pointrast::io

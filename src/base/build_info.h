// What the running binary was built from, for reports that must say which code they measured.
#pragma once

namespace pointrast {

// `git describe --always --dirty` of the source tree at build time ("076e1b6a2f3c", "076e1b6a2f3c-dirty"),
// or "unknown" for a build outside a git checkout.
const char* buildCommit();

} // namespace pointrast

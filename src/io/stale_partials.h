// Temporary names that carry their writer's pid ("<target>.partial-<pid>", see partialPath in io_util.h),
// and the removal of those whose writer no longer runs.
#pragma once

#include <filesystem>

namespace pointrast::io::detail {

// Removes what processes that no longer run left under "<target>.partial-<pid>" (files or folders): a
// build killed by SIGKILL, a second Ctrl-C or a file-size limit never ran its cleanup. Another live
// process's temporaries are kept.
void removeStalePartials(const std::filesystem::path& target);

} // namespace pointrast::io::detail

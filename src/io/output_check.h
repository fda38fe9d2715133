// Whether an output can be written, asked before any work: a render, a conversion or an octree build
// should not run for minutes and then fail on the name it was given.
#pragma once

#include <filesystem>
#include <string_view>

namespace pointrast::io {

// Throws InputError with one line when `target` (a file or a folder to be created; not created here) has
// no folder to go in: a folder on the way does not exist or is a file ("out.las/x.png": out.las is a
// file), or the folder refuses a new entry (a read-only file system, permissions). That last is asked of
// the file system by creating and removing a probe under the target's temporary name, not by access(),
// whose answer for root ignores permission bits. `option` names where the target came from ("-o").
void checkOutputTarget(const std::filesystem::path& target, std::string_view option);

} // namespace pointrast::io

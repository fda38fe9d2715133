#include "io/output_check.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include "base/error.h"
#include "io/io_util.h"

namespace pointrast::io {

void checkOutputTarget(const std::filesystem::path& target, std::string_view option) {
  namespace fs = std::filesystem;
  const std::string named = std::string(option) + " " + target.string();
  if (target.empty()) throw InputError(std::string(option) + ": give the name of the output");
  std::error_code ec;
  fs::path whole = fs::absolute(target, ec).lexically_normal();
  if (ec) throw InputError(named + ": " + ec.message());
  if (whole.filename().empty()) whole = whole.parent_path(); // "out/" names "out"
  const fs::path folder = whole.parent_path();
  // The deepest folder on the way that exists says what is wrong with the rest.
  fs::path existing = folder;
  while (!fs::exists(fs::symlink_status(existing, ec)) && existing.has_relative_path())
    existing = existing.parent_path();
  const fs::file_type type = fs::status(existing, ec).type();
  if (type != fs::file_type::directory && type != fs::file_type::not_found)
    throw InputError(named + ": " + existing.string() + " is a file, not a folder");
  if (existing != folder) throw InputError(named + ": the folder " + folder.string() + " does not exist");
  const fs::path probe = detail::partialPath(whole);
  int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0 && errno != EEXIST)
    throw InputError(named + ": cannot write in the folder " + folder.string() + " (" + std::strerror(errno) +
                     ")");
  if (fd >= 0) {
    ::close(fd);
    ::unlink(probe.c_str());
  }
}

} // namespace pointrast::io

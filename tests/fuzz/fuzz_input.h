// Shared by the libFuzzer targets: hands the fuzzer's bytes to a reader as a file. The readers work on
// paths (positional reads, file-size checks), so the input goes into an anonymous in-memory file
// (memfd) opened through /proc/self/fd: no disk traffic, nothing to clean up.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include <sys/mman.h>
#include <unistd.h>

#include "base/error.h"
#include "base/progress.h"
#include "io/reader.h"

namespace fuzz {

class MemFile {
public:
  MemFile(const uint8_t* data, size_t size) {
    fd_ = memfd_create("pointrast-fuzz", MFD_CLOEXEC);
    if (fd_ < 0) __builtin_trap();
    for (size_t done = 0; done < size;) {
      ssize_t n = ::write(fd_, data + done, size - done);
      if (n <= 0) __builtin_trap();
      done += static_cast<size_t>(n);
    }
    path_ = "/proc/self/fd/" + std::to_string(fd_);
  }
  ~MemFile() { ::close(fd_); }
  const std::filesystem::path& path() const { return path_; }

private:
  int fd_ = -1;
  std::filesystem::path path_;
};

// Runs read and probe; InputError is the expected way to refuse, anything else escapes and is a finding.
template <class Read, class Probe> int run(const uint8_t* data, size_t size, Read read, Probe probe) {
  pointrast::Progress::setEnabled(false);
  MemFile file(data, size);
  pointrast::io::ReadOptions options;
  options.progress = false;
  try {
    pointrast::PointCloud cloud = read(file.path(), options);
    if (cloud.positions.size() != 3 * cloud.size()) __builtin_trap();
  } catch (const pointrast::InputError&) {
  }
  try {
    probe(file.path());
  } catch (const pointrast::InputError&) {
  }
  return 0;
}

} // namespace fuzz

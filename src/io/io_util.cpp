#include "io/io_util.h"
#include "io/stale_partials.h"

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdarg>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base/text.h"

namespace pointrast::io::detail {

std::string strFormat(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  va_list copy;
  va_copy(copy, args);
  int n = std::vsnprintf(nullptr, 0, fmt, copy);
  va_end(copy);
  std::string out(n > 0 ? static_cast<size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, fmt, args);
  va_end(args);
  return out;
}

void fail(const std::filesystem::path& path, const std::string& message) {
  throw InputError(path.string() + ": " + message);
}

void warn(const std::filesystem::path& path, const std::string& message) {
  std::fprintf(stderr, "%s: warning: %s\n", printableLine(path.string()).c_str(),
               printableLine(message).c_str());
}

std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// ---- InputFile -------------------------------------------------------------------------------------

namespace {

// What a path is when it is not a regular file, for the refusal.
const char* fileTypeName(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a named pipe (FIFO)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "a special file";
}

} // namespace

InputFile::InputFile(const std::filesystem::path& path) : path_(path) {
  // O_NONBLOCK: a blocking open of a FIFO waits for a writer, forever. The type is then checked on the
  // open descriptor, so nothing can swap the file between the check and the reads; for a regular file
  // the flag changes nothing. O_NOCTTY: a terminal given as input must not become our controlling one.
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd_ < 0) fail(path, strFormat("cannot open: %s", std::strerror(errno)));
  struct stat st {};
  const bool statted = ::fstat(fd_, &st) == 0;
  const int error = errno;
  if (!statted || !S_ISREG(st.st_mode)) {
    ::close(fd_);
    fd_ = -1;
    if (!statted) fail(path, strFormat("cannot open: %s", std::strerror(error)));
    fail(path, strFormat("is %s, not a regular file", fileTypeName(st.st_mode)));
  }
  size_ = static_cast<uint64_t>(st.st_size);
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

size_t InputFile::readSome(uint64_t offset, void* dst, size_t n) const {
  if (offset >= size_) return 0;
  n = static_cast<size_t>(std::min<uint64_t>(n, size_ - offset));
  size_t done = 0;
  auto* out = static_cast<uint8_t*>(dst);
  while (done < n) {
    ssize_t got = ::pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) fail(path_, strFormat("read error: %s", std::strerror(errno)));
    if (got == 0) break; // the file shrank while we read it
    done += static_cast<size_t>(got);
  }
  return done;
}

void InputFile::readAt(uint64_t offset, void* dst, size_t n) const {
  if (offset > size_ || n > size_ - offset)
    fail(path_, strFormat("unexpected end of file (needed %zu bytes at offset %llu of %llu)", n,
                          static_cast<unsigned long long>(offset), static_cast<unsigned long long>(size_)));
  if (readSome(offset, dst, n) != n) fail(path_, "the file became shorter while it was read");
}

// ---- BufferedReader --------------------------------------------------------------------------------

BufferedReader::BufferedReader(const InputFile& file, uint64_t start, size_t window)
    : file_(file), bufferStart_(std::min(start, file.size())) {
  // No larger than the file needs: readers of tiny files (and truncation sweeps) stay cheap.
  buffer_.resize(static_cast<size_t>(std::clamp<uint64_t>(file.size() - bufferStart_, 1, window)));
}

size_t BufferedReader::fill(size_t n) {
  if (available() >= n) return n;
  // Slide the unread tail to the front, grow the window if one request is larger than it, then refill.
  size_t tail = available();
  std::memmove(buffer_.data(), buffer_.data() + cursor_, tail);
  bufferStart_ += cursor_;
  cursor_ = 0;
  end_ = tail;
  uint64_t left = file_.size() - bufferStart_ - tail;
  size_t want = static_cast<size_t>(std::min<uint64_t>(n - tail, left));
  if (tail + want > buffer_.size()) buffer_.resize(tail + want);
  size_t space = buffer_.size() - end_;
  size_t toRead = static_cast<size_t>(std::min<uint64_t>(space, left));
  size_t got = file_.readSome(bufferStart_ + end_, buffer_.data() + end_, toRead);
  end_ += got;
  return std::min(n, available());
}

const uint8_t* BufferedReader::require(size_t n, const char* what) {
  if (fill(n) < n)
    fail(file_.path(), strFormat("unexpected end of file in %s at byte %llu", what,
                                 static_cast<unsigned long long>(position())));
  return data();
}

void BufferedReader::skip(uint64_t n, const char* what) {
  if (n <= available()) {
    cursor_ += static_cast<size_t>(n);
    return;
  }
  if (n > remaining())
    fail(file_.path(), strFormat("unexpected end of file in %s at byte %llu", what,
                                 static_cast<unsigned long long>(position())));
  bufferStart_ = position() + n;
  cursor_ = end_ = 0;
}

// ---- PartialFile -----------------------------------------------------------------------------------

// "<target>.partial-<pid>": a process killed outright leaves its partial file, and the next writer of
// the same path removes it (its pid is gone) without touching another live writer's.
std::filesystem::path partialPath(const std::filesystem::path& target) {
  std::filesystem::path p = target;
  p += ".partial-" + std::to_string(::getpid());
  return p;
}

void removeStalePartials(const std::filesystem::path& target) {
  const std::filesystem::path dir = target.parent_path().empty() ? "." : target.parent_path();
  const std::string prefix = target.filename().string() + ".partial-";
  std::error_code ec;
  std::filesystem::directory_iterator it(dir, ec), end;
  std::vector<std::filesystem::path> stale;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = pid_t(std::stol(digits));
    // kill(pid, 0) fails with ESRCH only for a pid no process has (EPERM: one runs, of another user).
    if (pid <= 0 || pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    stale.push_back(it->path());
  }
  for (const auto& path : stale)
    std::filesystem::remove_all(path, ec);
}

PartialFile::PartialFile(std::filesystem::path target)
    : target_(std::move(target)), partial_(partialPath(target_)) {
  removeStalePartials(target_);
  file_ = std::fopen(partial_.c_str(), "wb");
  if (!file_) fail(target_, strFormat("cannot write: %s", std::strerror(errno)));
}

PartialFile::~PartialFile() {
  if (committed_) return;
  if (file_) std::fclose(file_);
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);
}

void PartialFile::failWrite(int error) {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);
  committed_ = true; // nothing left to clean up
  fail(target_, strFormat("cannot write: %s", std::strerror(error)));
}

void PartialFile::write(const void* data, size_t n) {
  if (n && std::fwrite(data, 1, n, file_) != n) failWrite(errno ? errno : EIO);
}

void PartialFile::writeAt(uint64_t offset, const void* data, size_t n) {
  if (std::fflush(file_) != 0 || ::fseeko(file_, static_cast<off_t>(offset), SEEK_SET) != 0)
    failWrite(errno ? errno : EIO);
  write(data, n);
  if (::fseeko(file_, 0, SEEK_END) != 0) failWrite(errno ? errno : EIO);
}

void PartialFile::commit() {
  errno = 0;
  int flushed = std::fflush(file_);
  int error = errno;
  int closed = std::fclose(file_);
  if (!error) error = errno;
  file_ = nullptr;
  if (flushed != 0 || closed != 0) failWrite(error ? error : EIO);
  std::error_code ec;
  std::filesystem::rename(partial_, target_, ec);
  if (ec) failWrite(ec.value());
  committed_ = true;
}

// ---- quantization ----------------------------------------------------------------------------------

Quantization chooseQuantization(const std::filesystem::path& path, const Bounds& bounds) {
  Quantization q;
  if (bounds.empty()) return q;
  for (int a = 0; a < 3; ++a) {
    double extent = bounds.max[a] - bounds.min[a];
    if (!std::isfinite(extent))
      fail(path, strFormat("coordinates span %g .. %g, too wide to store", bounds.min[a], bounds.max[a]));
    q.offset[a] = bounds.min[a];
    double scale = 1.0;
    if (extent > 0) {
      // The smallest power of ten with extent / scale <= kQuantSteps; log10 only gives the start. The
      // logarithms are taken apart: a subnormal extent divided by kQuantSteps is 0, whose log is -inf.
      double start = std::ceil(std::log10(extent) - std::log10(kQuantSteps));
      int k = static_cast<int>(std::clamp(start, -300.0, 300.0));
      while (k > -300 && extent / std::pow(10.0, k - 1) <= kQuantSteps)
        --k;
      while (k < 300 && extent / std::pow(10.0, k) > kQuantSteps)
        ++k;
      scale = std::pow(10.0, k);
    }
    q.scale[a] = scale;
  }
  return q;
}

Bounds boundsFromQuantized(const int32_t qmin[3], const int32_t qmax[3], const glm::dvec3& scale,
                           const glm::dvec3& offset) {
  Bounds b;
  for (int a = 0; a < 3; ++a) {
    double lo = qmin[a] * scale[a] + offset[a];
    double hi = qmax[a] * scale[a] + offset[a];
    b.min[a] = std::min(lo, hi);
    b.max[a] = std::max(lo, hi);
  }
  return b;
}

} // namespace pointrast::io::detail

#include "io/media/video_writer.h"

#include <cassert>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <system_error>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/error.h"

extern char** environ;

namespace pointrast::io {

namespace {

std::string format(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

// Writes all of `size` bytes; false when the reader is gone (EPIPE) or the pipe failed.
bool writeAll(int fd, const char* data, size_t size) {
  while (size > 0) {
    ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= size_t(n);
  }
  return true;
}

// Ignores SIGPIPE for the life of the process once a video is written: a failed ffmpeg must turn into an
// EPIPE error from write(), not a signal that kills pointrast before it can clean up.
void ignoreSigpipe() {
  static bool done = [] {
    std::signal(SIGPIPE, SIG_IGN);
    return true;
  }();
  (void)done;
}

} // namespace

const char* videoContainer(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  if (ext == ".mp4") return "mp4";
  if (ext == ".mkv") return "matroska";
  throw InputError(path.string() + ": the video must be a .mp4 or .mkv file");
}

VideoWriter::VideoWriter(const std::filesystem::path& path, const VideoOptions& options)
    : path_(path), partial_(path.string() + ".partial"), options_(options) {
  const char* container = videoContainer(path);
  if (options.width == 0 || options.height == 0 || options.width % 2 || options.height % 2)
    throw InputError(path.string() + ": H.264 video needs an even width and height, not " +
                     std::to_string(options.width) + "x" + std::to_string(options.height));
  if (!(options.fps > 0 && options.fps <= 1000))
    throw InputError("--fps must be between 0 and 1000, not " + format(options.fps));
  if (options_.ffmpeg.empty()) {
    const char* env = std::getenv("POINTRAST_FFMPEG");
    options_.ffmpeg = env && *env ? env : "ffmpeg";
  }
  ignoreSigpipe();
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0)
    throw InputError("cannot create a pipe to ffmpeg: " + std::string(strerror(errno)));
  std::string size = std::to_string(options.width) + "x" + std::to_string(options.height);
  std::vector<std::string> args = {
      options_.ffmpeg, "-hide_banner", "-loglevel", "error", "-nostdin", "-y",
      // raw RGBA frames on stdin, row 0 at the top
      "-f", "rawvideo", "-pix_fmt", "rgba", "-s", size, "-r", format(options.fps), "-i", "pipe:0",
      // H.264 that every player reads
      "-c:v", "libx264", "-preset", "medium", "-crf", std::to_string(options.crf), "-pix_fmt", "yuv420p",
      "-movflags", "+faststart", "-f", container, partial_.string()};
  std::vector<char*> argv;
  for (std::string& a : args)
    argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], STDIN_FILENO);
  // ffmpeg's stdout would mix with a --json line; its errors go to our stderr.
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  int spawned = posix_spawnp(&pid_, options_.ffmpeg.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (spawned != 0) {
    ::close(fds[1]);
    pid_ = -1;
    throw UnsupportedError(
        "cannot start '" + options_.ffmpeg + "' (" + strerror(spawned) +
        "): video output needs ffmpeg (`apt-get install ffmpeg`), or write PNG frames with "
        "--frames-dir instead");
  }
  pipe_ = fds[1];
}

VideoWriter::~VideoWriter() {
  if (!finished_) abort();
}

void VideoWriter::abort() {
  if (pipe_ >= 0) ::close(pipe_);
  pipe_ = -1;
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
  }
  std::error_code ignored;
  std::filesystem::remove(partial_, ignored);
}

void VideoWriter::write(const uint32_t* rgba) {
  assert(!finished_ && pipe_ >= 0 && "write after finish");
  size_t bytes = size_t(options_.width) * options_.height * 4;
  if (!writeAll(pipe_, reinterpret_cast<const char*>(rgba), bytes)) {
    abort();
    throw InputError(path_.string() + ": ffmpeg stopped reading frames before the last one (it failed); no video written");
  }
  ++frames_;
}

void VideoWriter::finish() {
  if (finished_) return;
  ::close(pipe_);
  pipe_ = -1;
  int status = 0;
  pid_t waited;
  while ((waited = waitpid(pid_, &status, 0)) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  bool ok = waited > 0 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!ok) {
    abort();
    throw InputError(path_.string() + ": ffmpeg failed (" +
                     (WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                                        : std::string("killed by a signal")) +
                     "); no video written");
  }
  std::error_code error;
  std::filesystem::rename(partial_, path_, error);
  if (error) {
    abort();
    throw InputError(path_.string() + ": cannot rename the finished video into place (" + error.message() +
                     ")");
  }
  finished_ = true;
}

} // namespace pointrast::io

// Video files through ffmpeg (Debian's package, libx264), run as a separate process that reads raw RGBA
// frames from a pipe. Like every writer, the video is written to "<path>.partial" and renamed only when
// ffmpeg finished successfully; on any failure (or when the writer is destroyed unfinished) ffmpeg is
// killed and the partial file removed, so no half-written video is ever left under the requested name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <sys/types.h>

namespace pointrast::io {

struct VideoOptions {
  uint32_t width = 0, height = 0; // even: H.264 in yuv420p halves the chroma resolution
  double fps = 60;
  // The encoder's constant rate factor (0 lossless .. 51; 18 is visually lossless for most content).
  uint32_t crf = 18;
  // The ffmpeg executable: $POINTRAST_FFMPEG when set, else "ffmpeg" on the PATH.
  std::string ffmpeg;
};

// The container for a file name: "mp4" for .mp4, "matroska" for .mkv; InputError for anything else.
const char* videoContainer(const std::filesystem::path& path);

class VideoWriter {
public:
  // Starts ffmpeg. Throws InputError for an odd size or an unknown extension, UnsupportedError when ffmpeg
  // cannot be started (naming the package to install).
  VideoWriter(const std::filesystem::path& path, const VideoOptions& options);
  ~VideoWriter();
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // One frame of width x height RGBA8 pixels, row 0 at the top. Throws InputError when ffmpeg stopped
  // reading (it failed; its own message is on stderr).
  void write(const uint32_t* rgba);
  // Closes the pipe, waits for ffmpeg and renames the video into place; InputError when ffmpeg failed.
  void finish();
  uint64_t frames() const { return frames_; }

private:
  void abort();
  std::filesystem::path path_, partial_;
  VideoOptions options_;
  pid_t pid_ = -1;
  int pipe_ = -1;
  uint64_t frames_ = 0;
  bool finished_ = false;
};

} // namespace pointrast::io

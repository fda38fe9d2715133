// A progress line on stderr for long work (loading, generating, uploading). It draws only when stderr is
// a terminal, at most ~10 times per second, and is safe to advance from several threads.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace pointrast {

class Progress {
public:
  // total: units of work (points, bytes); label: what is being done ("reading autzen.las");
  // show = false keeps it silent (the caller asked for no progress).
  Progress(std::string label, uint64_t total, std::string unit = " points", bool show = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(uint64_t units);
  // Ends the line; prints a summary line ("... 1.2 G points in 3.1 s, 390 M points/s") when verbose.
  void finish();
  double seconds() const;
  uint64_t done() const { return done_.load(std::memory_order_relaxed); }

  // Global switch: the CLI's --quiet turns all progress and summaries off.
  static void setEnabled(bool enabled);
  static bool enabled();

private:
  void draw(bool final);
  std::string label_;
  std::string unit_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::atomic<int64_t> lastDrawNs_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex drawMutex_;
  bool tty_;
  bool show_;
  bool finished_ = false;
};

// "1.20 G", "345 M", "12.0 k": compact counts for messages.
std::string humanCount(double value);

} // namespace pointrast

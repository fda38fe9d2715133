#include "base/progress.h"

#include <cstdio>
#include <unistd.h>

namespace pointrast {

namespace {
std::atomic<bool> gEnabled{true};
}

void Progress::setEnabled(bool enabled) {
  gEnabled = enabled;
}
bool Progress::enabled() {
  return gEnabled;
}

std::string humanCount(double value) {
  char buf[32];
  if (value >= 1e9)
    std::snprintf(buf, sizeof buf, "%.2f G", value / 1e9);
  else if (value >= 1e6)
    std::snprintf(buf, sizeof buf, "%.1f M", value / 1e6);
  else if (value >= 1e3)
    std::snprintf(buf, sizeof buf, "%.1f k", value / 1e3);
  else
    std::snprintf(buf, sizeof buf, "%.0f", value);
  return buf;
}

Progress::Progress(std::string label, uint64_t total, std::string unit, bool show)
    : label_(std::move(label)), unit_(std::move(unit)), total_(total),
      start_(std::chrono::steady_clock::now()), tty_(isatty(STDERR_FILENO) != 0), show_(show) {}

Progress::~Progress() {
  finish();
}

double Progress::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::advance(uint64_t units) {
  done_.fetch_add(units, std::memory_order_relaxed);
  if (!tty_ || !show_ || !gEnabled) return;
  int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                    std::chrono::steady_clock::now().time_since_epoch())
                    .count();
  int64_t last = lastDrawNs_.load(std::memory_order_relaxed);
  if (now - last < 100'000'000) return;
  if (!lastDrawNs_.compare_exchange_strong(last, now)) return;
  draw(false);
}

void Progress::draw(bool final) {
  std::lock_guard lock(drawMutex_);
  double done = static_cast<double>(done_.load());
  double secs = seconds();
  double pct = total_ ? 100.0 * done / static_cast<double>(total_) : 100.0;
  double rate = secs > 0 ? done / secs : 0;
  if (tty_) {
    std::fprintf(stderr, "\r\033[K%s: %5.1f%%  %s%s  %s%s/s", label_.c_str(), pct, humanCount(done).c_str(),
                 unit_.c_str(), humanCount(rate).c_str(), unit_.c_str());
    // The time left at the rate so far, once there is a rate to go by.
    if (!final && total_ && rate > 0 && done < double(total_))
      std::fprintf(stderr, "  ETA %.0f s", (double(total_) - done) / rate);
  }
  if (final) {
    if (tty_) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "%s: %s%s in %.2f s (%s%s/s)\n", label_.c_str(), humanCount(done).c_str(),
                 unit_.c_str(), secs, humanCount(rate).c_str(), unit_.c_str());
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  // The summary line is for work long enough to care about (it also reports throughput in logs).
  if (show_ && gEnabled && (seconds() >= 0.5 || lastDrawNs_.load() != 0)) draw(true);
}

} // namespace pointrast

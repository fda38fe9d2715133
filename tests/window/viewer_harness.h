// Driving `pointrast view` as a user would, on a private Xvfb server: the viewer's --events lines read from
// its stdout, input sent with xdotool (XTEST), the window read back with XGetImage.
#pragma once

#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "test_data.h"
#include "x11_capture.h"

namespace pointrast::test {

using Clock = std::chrono::steady_clock;

// The output of a shell command (stderr dropped).
inline std::string shellOutput(const std::string& command) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0)
    out.append(buffer, n);
  pclose(pipe);
  return out;
}

// An Xvfb server on a free display number (-displayfd), killed on destruction.
class Xvfb {
public:
  Xvfb() {
    int fds[2];
    if (pipe(fds) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      close(fds[0]);
      int devnull = open("/dev/null", O_WRONLY);
      dup2(devnull, STDOUT_FILENO);
      dup2(devnull, STDERR_FILENO);
      std::string fd = std::to_string(fds[1]);
      execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1280x1024x24", "-nolisten", "tcp",
             "-noreset", static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    std::string number;
    char c;
    while (read(fds[0], &c, 1) == 1 && c != '\n')
      number += c;
    close(fds[0]);
    if (!number.empty()) display_ = ":" + number;
  }
  ~Xvfb() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
  }
  const std::string& display() const { return display_; } // empty: Xvfb did not start

private:
  pid_t pid_ = -1;
  std::string display_;
};

// A running `pointrast view ... --events`; its events are collected by a reader thread. `launcher` goes
// before the binary (e.g. mpirun and its options).
class Viewer {
public:
  Viewer(const std::string& display, const std::string& args, const std::string& launcher = "")
      : display_(display) {
    int fds[2];
    if (pipe(fds) != 0) return;
    errFile_ =
        std::filesystem::temp_directory_path() / ("pointrast_view_err_" + std::to_string(getpid()) + ".txt");
    pid_ = fork();
    if (pid_ == 0) {
      close(fds[0]);
      dup2(fds[1], STDOUT_FILENO);
      int err = open(errFile_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(err, STDERR_FILENO);
      setenv("DISPLAY", display.c_str(), 1);
      setenv("XDG_RUNTIME_DIR", "/tmp", 1);
      if (!getenv("POINTRAST_VALIDATION")) setenv("POINTRAST_VALIDATION", "1", 1);
      std::string command = "exec " + launcher + " '" + pointrastBinary() + "' view " + args + " --events -q";
      execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    reader_ = std::thread([this, fd = fds[0]] {
      std::string line;
      char buffer[4096];
      ssize_t n;
      while ((n = read(fd, buffer, sizeof buffer)) > 0)
        for (ssize_t i = 0; i < n; ++i) {
          if (buffer[i] != '\n') {
            line += buffer[i];
            continue;
          }
          std::lock_guard lock(mutex_);
          events_.push_back(nlohmann::json::parse(line, nullptr, false));
          line.clear();
          arrived_.notify_all();
        }
      close(fd);
      std::lock_guard lock(mutex_);
      closed_ = true;
      arrived_.notify_all();
    });
  }

  ~Viewer() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (reader_.joinable()) reader_.join();
    std::filesystem::remove(errFile_);
  }

  // The first event after index `from` that satisfies `match`, waiting up to `seconds`.
  std::optional<nlohmann::json> waitFor(const std::function<bool(const nlohmann::json&)>& match,
                                        size_t from = 0, double seconds = 60) {
    std::unique_lock lock(mutex_);
    auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
    for (size_t i = from;;) {
      for (; i < events_.size(); ++i)
        if (events_[i].is_object() && match(events_[i])) return events_[i];
      if (closed_ || !arrived_.wait_until(lock, deadline, [&] { return events_.size() > i || closed_; })) {
        for (; i < events_.size(); ++i)
          if (events_[i].is_object() && match(events_[i])) return events_[i];
        return std::nullopt;
      }
    }
  }
  std::optional<nlohmann::json> waitEvent(const std::string& name, size_t from = 0, double seconds = 60) {
    return waitFor([&](const nlohmann::json& e) { return e.value("event", "") == name; }, from, seconds);
  }
  size_t eventCount() {
    std::lock_guard lock(mutex_);
    return events_.size();
  }

  // The viewer's X window (its title starts with "pointrast").
  unsigned long window() {
    if (!window_) {
      std::string out =
          shellOutput("DISPLAY=" + display_ + " xdotool search --sync --name '^pointrast' 2>/dev/null");
      window_ = std::strtoul(out.c_str(), nullptr, 10);
    }
    return window_;
  }
  // xdotool with the window's id in $W, e.g. "mousemove --window $W 10 10 click 1".
  int xdotool(const std::string& commands) {
    std::string command =
        "DISPLAY=" + display_ + " W=" + std::to_string(window()) + " sh -c 'xdotool " + commands + "'";
    return std::system(command.c_str());
  }

  // Escape, then the exit status (-1 when it did not exit within the time).
  int quit(double seconds = 60) {
    xdotool("mousemove --window $W 5 5 key Escape");
    auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
    int status = 0;
    while (Clock::now() < deadline) {
      pid_t r = waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return -1;
  }
  std::string errors() const {
    std::FILE* f = std::fopen(errFile_.c_str(), "r");
    std::string text;
    if (!f) return text;
    char buffer[4096];
    size_t n;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0)
      text.append(buffer, n);
    std::fclose(f);
    return text;
  }

private:
  std::string display_;
  pid_t pid_ = -1;
  bool exited_ = false;
  std::filesystem::path errFile_;
  std::thread reader_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<nlohmann::json> events_;
  bool closed_ = false;
  unsigned long window_ = 0;
};

} // namespace pointrast::test

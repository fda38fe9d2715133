// Driving `pointrast serve` as a user would: the server started with --port 0 --events (its JSON lines read
// from stdout), stopped with a signal, its exit code and exit event checked; requests and WebSockets from
// the load tool's client; chromium through tests/web/browser.mjs.
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

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "test_data.h"

namespace pointrast::test {

using Json = nlohmann::json;

inline std::string autzen() {
  return (dataDir() / "las" / "autzen_trim.las").string();
}

// A camera that sees most of autzen_trim from the south-west, above.
constexpr const char* kAutzenCamera = "--eye 636000,848900,700 --target 636600,849200,450";

// The output of a shell command, stderr dropped.
inline std::string commandOutput(const std::string& command) {
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

inline std::filesystem::path scratchDir(const std::string& name) {
  auto dir =
      std::filesystem::temp_directory_path() / ("pointrast_web_" + name + "_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

class ServeProcess {
public:
  // `launcher`: a command the server is started under (mpirun and its options), before the binary.
  explicit ServeProcess(const std::string& args, const std::string& launcher = "") {
    int fds[2];
    if (pipe(fds) != 0) return;
    errFile_ = scratchDir("server") / ("stderr_" + std::to_string(counter()++) + ".txt");
    pid_ = fork();
    if (pid_ == 0) {
      close(fds[0]);
      dup2(fds[1], STDOUT_FILENO);
      int err = open(errFile_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(err, STDERR_FILENO);
      setenv("XDG_RUNTIME_DIR", "/tmp", 1);
      if (!getenv("POINTRAST_VALIDATION")) setenv("POINTRAST_VALIDATION", "1", 1);
      std::string command =
          "exec " + launcher + " '" + pointrastBinary() + "' serve " + args + " --port 0 --events -q";
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
          events_.push_back(Json::parse(line, nullptr, false));
          line.clear();
          arrived_.notify_all();
        }
      close(fd);
      std::lock_guard lock(mutex_);
      ended_ = true;
      arrived_.notify_all();
    });
    if (auto e = waitFor([](const Json& j) { return j.value("event", "") == "listening"; }, 120)) {
      url_ = (*e)["url"];
      port_ = (*e)["port"];
    }
  }
  ~ServeProcess() {
    if (pid_ > 0 && status_ < 0) stop();
    if (reader_.joinable()) reader_.join();
  }

  bool listening() const { return port_ != 0; }
  const std::string& url() const { return url_; }
  uint16_t port() const { return port_; }
  std::string stderrText() const { return commandOutput("cat '" + errFile_.string() + "'"); }

  std::optional<Json> waitFor(const std::function<bool(const Json&)>& match, double seconds) {
    std::unique_lock lock(mutex_);
    std::optional<Json> found;
    arrived_.wait_for(lock, std::chrono::duration<double>(seconds), [&] {
      for (const Json& e : events_)
        if (e.is_object() && match(e)) {
          found = e;
          return true;
        }
      return ended_;
    });
    return found;
  }
  std::vector<Json> events() {
    std::lock_guard lock(mutex_);
    return events_;
  }
  bool alive() {
    if (pid_ <= 0 || status_ >= 0) return false;
    int s = 0;
    if (waitpid(pid_, &s, WNOHANG) != pid_) return true;
    status_ = s;
    return false;
  }

  // Sends the signal and waits (at most 60 s) for the exit; returns the exit code, or 128 + the signal that
  // killed it, or -1 when it did not stop.
  int stop(int signal = SIGTERM) {
    if (pid_ <= 0) return -1;
    if (status_ >= 0) return code();
    kill(pid_, signal);
    for (int i = 0; i < 600; ++i) {
      if (waitpid(pid_, &status_, WNOHANG) == pid_) return code();
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, &status_, 0);
    return -1;
  }
  std::optional<Json> exitEvent() {
    return waitFor([](const Json& j) { return j.value("event", "") == "exit"; }, 5);
  }

private:
  static int& counter() {
    static int n = 0;
    return n;
  }
  int code() const { return WIFEXITED(status_) ? WEXITSTATUS(status_) : 128 + WTERMSIG(status_); }
  pid_t pid_ = -1;
  int status_ = -1;
  std::filesystem::path errFile_;
  std::thread reader_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<Json> events_;
  bool ended_ = false;
  std::string url_;
  uint16_t port_ = 0;
};

// Runs a scenario of browser.mjs (chromium through playwright-core) against url, its files in outdir; its
// last line is the JSON result, a failure it reports fails the test.
inline Json browser(const std::string& scenario, const std::string& url, const std::filesystem::path& outdir,
                    const Json& args) {
  const std::string dir = std::string(POINTRAST_SOURCE_DIR) + "/tests/web";
  const std::string out = commandOutput("cd '" + dir + "' && node browser.mjs " + scenario + " '" + url +
                                        "' '" + outdir.string() + "' '" + args.dump() + "' 2>&1");
  const size_t last = out.rfind('\n', out.size() >= 2 ? out.size() - 2 : 0);
  Json result = Json::parse(last == std::string::npos ? out : out.substr(last + 1), nullptr, false);
  if (!result.is_object()) ADD_FAILURE() << "browser.mjs " << scenario << " printed:\n" << out;
  if (result.is_object() && result.contains("failure")) ADD_FAILURE() << result["failure"].get<std::string>();
  return result.is_object() ? result : Json::object();
}

} // namespace pointrast::test

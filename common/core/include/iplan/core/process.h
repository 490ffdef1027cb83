// Child processes: real executables started with their own arguments and
// environment, output captured to files (used by `iplan demo` and by the
// multi-process tests).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace iplan::core {

class Process {
 public:
  /// Starts `argv[0]` (a path) with `argv`, the current environment plus
  /// `env`. stdout and stderr go to files under $TMPDIR, or are inherited
  /// when `inherit_output`; with a `log_base` they go to `log_base`.out and
  /// .err and are kept after the process object is gone. Throws
  /// std::runtime_error on failure.
  Process(std::vector<std::string> argv, std::map<std::string, std::string> env = {},
          bool inherit_output = false, const std::string& log_base = "");
  ~Process();  // SIGKILL if still running
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  pid_t pid() const { return pid_; }
  /// Sends a signal.
  void Signal(int sig);
  /// Waits for exit; nullopt on timeout. Returns the exit code, or 128 + the
  /// signal number when killed by a signal.
  std::optional<int> Wait(std::chrono::milliseconds timeout);
  bool Running();
  std::string Stdout() const;
  std::string Stderr() const;
  /// Waits until stdout contains `text`; false on timeout or exit.
  bool WaitForOutput(const std::string& text, std::chrono::milliseconds timeout);

 private:
  pid_t pid_ = -1;
  std::optional<int> exit_code_;
  std::string out_path_, err_path_;
  bool keep_logs_ = false;
};

/// The folder of the running executable (from /proc/self/exe).
std::string ExecutableDir();

}  // namespace iplan::core

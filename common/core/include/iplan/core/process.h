// Child processes: real executables started with their own arguments and
// environment, output captured to files (used by `iplan demo` and by the
// multi-process tests).
//
// A child never outlives its parent: it is started with a parent-death
// signal (SIGTERM, Linux's PR_SET_PDEATHSIG), so however the parent ends
// (exit, SIGINT, SIGKILL, a crash) every child it started is told to stop,
// and the services stop as they do on SIGTERM. The kernel sends that signal
// when the *thread* that started the child ends: start children from a
// thread that lives as long as they should (the main thread, as `iplan demo`
// and the tests do).
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
  /// .err and are kept after the process object is gone. The child gets
  /// SIGTERM when the calling thread ends (see above). Throws
  /// std::runtime_error when the executable cannot be started (not found,
  /// not executable, a log file that cannot be opened), with the reason.
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

/// Pins the calling thread (and threads it starts later) to the CPU it runs
/// on now: single-threaded benchmarks keep their cache and comparable
/// figures. Returns false when the kernel refuses.
bool PinToCurrentCpu();

}  // namespace iplan::core

// Child processes for multi-process tests: real executables, started with
// their own arguments and environment, output captured to files.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace iplan::testing {

class Process {
 public:
  /// Starts `argv[0]` (a path) with `argv`, the current environment plus
  /// `env`, stdout and stderr to files under $TMPDIR. Throws on failure.
  Process(std::vector<std::string> argv, std::map<std::string, std::string> env = {});
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
};

/// build/bin/<name>.
std::string BinPath(const std::string& name);
/// build/tests/<name>.
std::string TestBinPath(const std::string& name);
/// A DDS domain id unique to this test process (from the pid), so tests can
/// run in parallel without hearing each other.
int UniqueDomain(int offset = 0);

}  // namespace iplan::testing

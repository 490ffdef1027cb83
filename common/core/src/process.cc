#include "iplan/core/process.h"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace iplan::core {
namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The child's side of Process: stdin from /dev/null, stdout and stderr to
// the log files (out == nullptr: inherited), default signal dispositions, a
// parent-death signal, then the executable. Async-signal-safe only; on
// failure the errno goes to `report` and the child exits 127.
[[noreturn]] void ExecChild(char* const* argv, char* const* envp, const char* out, const char* err, pid_t parent,
                            int report) {
  auto die = [&](int e) {
    ssize_t ignored = write(report, &e, sizeof e);
    (void)ignored;
    _exit(127);
  };
  if (prctl(PR_SET_PDEATHSIG, SIGTERM) != 0) die(errno);
  if (getppid() != parent) _exit(128 + SIGTERM);  // the parent died before the line above
  const int in = open("/dev/null", O_RDONLY);
  if (in < 0 || dup2(in, 0) < 0) die(errno);
  if (out) {
    const int o = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (o < 0 || dup2(o, 1) < 0) die(errno);
    const int e = open(err, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (e < 0 || dup2(e, 2) < 0) die(errno);
  }
  // The parent's signal dispositions that are not defaults (an ignored
  // SIGINT, say) must not reach the service, nor its blocked mask.
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  for (const int sig : {SIGINT, SIGTERM, SIGPIPE, SIGHUP}) sigaction(sig, &dfl, nullptr);
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  execve(argv[0], argv, envp);
  die(errno);
  _exit(127);  // not reached: die exits
}

}  // namespace

Process::Process(std::vector<std::string> argv, std::map<std::string, std::string> env, bool inherit_output,
                 const std::string& log_base) {
  static int counter = 0;
  const char* tmp = std::getenv("TMPDIR");
  keep_logs_ = !log_base.empty();
  const std::string base = keep_logs_ ? log_base
                                      : std::string(tmp && *tmp ? tmp : "/tmp") + "/iplan-test-" +
                                            std::to_string(getpid()) + "-" + std::to_string(counter++);
  out_path_ = base + ".out";
  err_path_ = base + ".err";

  std::map<std::string, std::string> all;
  for (char** e = environ; *e; ++e) {
    const char* eq = std::strchr(*e, '=');
    if (eq) all[std::string(*e, static_cast<std::size_t>(eq - *e))] = eq + 1;
  }
  for (auto& [k, v] : env) all[k] = v;
  std::vector<std::string> env_strings;
  for (auto& [k, v] : all) env_strings.push_back(k + "=" + v);
  std::vector<char*> envp, args;
  for (auto& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  for (auto& s : argv) args.push_back(s.data());
  args.push_back(nullptr);

  // fork + exec rather than posix_spawn: the child has to ask for a
  // parent-death signal before it runs the executable, so that a child
  // never outlives the process that started it, however that one ends
  // (SIGKILL and crashes included). Between fork and exec only
  // async-signal-safe calls (the parent may have DDS threads).
  const char* out = out_path_.c_str();
  const char* err = err_path_.c_str();
  int report[2];  // the child writes errno here when it cannot start
  if (pipe2(report, O_CLOEXEC) != 0) throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(errno));
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ < 0) {
    const int e = errno;
    close(report[0]);
    close(report[1]);
    throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(e));
  }
  if (pid_ == 0) ExecChild(args.data(), envp.data(), inherit_output ? nullptr : out, err, parent, report[1]);
  close(report[1]);
  int child_errno = 0;
  ssize_t n;
  do {
    n = read(report[0], &child_errno, sizeof child_errno);
  } while (n < 0 && errno == EINTR);
  close(report[0]);
  if (n == static_cast<ssize_t>(sizeof child_errno)) {
    int status = 0;
    waitpid(pid_, &status, 0);
    pid_ = -1;
    exit_code_ = 127;
    throw std::runtime_error("cannot start " + argv[0] + ": " + std::strerror(child_errno));
  }
}

Process::~Process() {
  if (pid_ > 0 && Running()) {
    kill(pid_, SIGKILL);
    Wait(std::chrono::milliseconds(5000));
  }
  if (!keep_logs_) {
    std::remove(out_path_.c_str());
    std::remove(err_path_.c_str());
  }
}

void Process::Signal(int sig) {
  if (!exit_code_ && pid_ > 0) kill(pid_, sig);
}

std::optional<int> Process::Wait(std::chrono::milliseconds timeout) {
  if (exit_code_) return exit_code_;
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return exit_code_;
    }
    if (std::chrono::steady_clock::now() >= end) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

bool Process::Running() { return !Wait(std::chrono::milliseconds(0)).has_value(); }

std::string Process::Stdout() const { return ReadFile(out_path_); }
std::string Process::Stderr() const { return ReadFile(err_path_); }

bool Process::WaitForOutput(const std::string& text, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (Stdout().find(text) != std::string::npos) return true;
    if (!Running() || std::chrono::steady_clock::now() >= end) return Stdout().find(text) != std::string::npos;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::string ExecutableDir() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  if (n <= 0) return ".";
  std::string path(buf, static_cast<std::size_t>(n));
  return path.substr(0, path.rfind('/'));
}

bool PinToCurrentCpu() {
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(sched_getcpu(), &one);
  return sched_setaffinity(0, sizeof one, &one) == 0;
}

}  // namespace iplan::core

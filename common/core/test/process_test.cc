// core::Process: a child that cannot start says why; a child never outlives
// the process that started it, however that process ends.
#include "iplan/core/process.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace iplan::core {
namespace {

using namespace std::chrono_literals;

// A process is gone when /proc has no entry for it or it is a zombie
// (reaped later by whoever inherited it).
bool Gone(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  if (!stat) return true;
  std::string line;
  std::getline(stat, line);
  const auto close = line.rfind(')');
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
}

bool GoneWithin(pid_t pid, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (Gone(pid)) return true;
    std::this_thread::sleep_for(10ms);
  }
  return Gone(pid);
}

TEST(ProcessTest, RunsAndReportsExitCode) {
  Process p({"/bin/sh", "-c", "echo hello; echo oops >&2; exit 3"});
  EXPECT_EQ(p.Wait(10s), 3);
  EXPECT_EQ(p.Stdout(), "hello\n");
  EXPECT_EQ(p.Stderr(), "oops\n");
}

TEST(ProcessTest, MissingExecutableThrowsWithReason) {
  try {
    Process p({"/nonexistent/iplan-nothing"});
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot start /nonexistent/iplan-nothing: No such file"), std::string::npos)
        << e.what();
  }
}

TEST(ProcessTest, SignalledChildReportsSignal) {
  Process p({"/bin/sleep", "30"});
  ASSERT_TRUE(p.Running());
  p.Signal(SIGTERM);
  EXPECT_EQ(p.Wait(5s), 128 + SIGTERM);
}

// A middle process (a fork of this test) starts a child with Process, tells
// us its pid and is then killed with SIGKILL, so no destructor runs: the
// child must still be gone within 2 s.
void ExpectChildDiesWithParent(bool kill_parent) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t middle = fork();
  ASSERT_GE(middle, 0);
  if (middle == 0) {
    close(fds[0]);
    auto* child = new Process({"/bin/sleep", "60"});  // never destroyed
    const pid_t pid = child->pid();
    if (write(fds[1], &pid, sizeof pid) != sizeof pid) _exit(2);
    if (kill_parent) {
      pause();  // until the SIGKILL below
    }
    _exit(0);  // an exit without destructors
  }
  close(fds[1]);
  pid_t child = -1;
  ASSERT_EQ(read(fds[0], &child, sizeof child), static_cast<ssize_t>(sizeof child));
  close(fds[0]);
  ASSERT_GT(child, 0);
  if (kill_parent) {
    EXPECT_FALSE(Gone(child)) << "the child must be running while its parent is";
    kill(middle, SIGKILL);
  }
  int status = 0;
  waitpid(middle, &status, 0);
  EXPECT_TRUE(GoneWithin(child, 2000ms)) << "child " << child << " outlived its parent";
  if (!Gone(child)) kill(child, SIGKILL);
}

TEST(ProcessTest, ChildDiesWhenParentIsKilled) { ExpectChildDiesWithParent(true); }
TEST(ProcessTest, ChildDiesWhenParentExitsWithoutCleanUp) { ExpectChildDiesWithParent(false); }

}  // namespace
}  // namespace iplan::core

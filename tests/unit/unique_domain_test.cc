// The DDS domain lease of the multi-process tests (tests/support/test_paths.h):
// two processes never hold the same domain, and a lease lasts until its
// holder exits.
#include <sys/wait.h>
#include <unistd.h>

#include <set>

#include <gtest/gtest.h>

#include "test_paths.h"

namespace iplan::testing {
namespace {

// Leases `n` domains in a child process and reports them through a pipe; the
// child then waits for a byte on `hold` before it exits (holding its leases).
struct Child {
  pid_t pid = -1;
  int report = -1, hold = -1;
};

Child LeaseInChild(int n) {
  int up[2], down[2];
  EXPECT_EQ(::pipe(up), 0);
  EXPECT_EQ(::pipe(down), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(up[0]);
    ::close(down[1]);
    for (int i = 0; i < n; ++i) {
      const int d = UniqueDomain(i);
      if (::write(up[1], &d, sizeof d) != sizeof d) ::_exit(2);
    }
    char c;
    (void)::read(down[0], &c, 1);
    ::_exit(0);
  }
  ::close(up[1]);
  ::close(down[0]);
  return {pid, up[0], down[1]};
}

TEST(UniqueDomain, TheSameOffsetGivesTheSameDomainAndOthersDiffer) {
  const int a = UniqueDomain(5), b = UniqueDomain(6);
  EXPECT_EQ(UniqueDomain(5), a);
  EXPECT_NE(a, b);
  for (int d : {a, b}) {
    EXPECT_GE(d, 1);
    EXPECT_LE(d, kLastTestDomain);
  }
}

TEST(UniqueDomain, ProcessesRunningTogetherNeverShareADomain) {
  std::set<int> mine;
  for (int i = 0; i < 8; ++i) mine.insert(UniqueDomain(100 + i));
  ASSERT_EQ(mine.size(), 8u);
  // Children with the same offsets as each other: a pid hash alone could
  // give them the same ids; the lease cannot.
  std::vector<Child> children;
  for (int c = 0; c < 6; ++c) children.push_back(LeaseInChild(8));
  std::set<int> all = mine;
  for (auto& ch : children) {
    for (int i = 0; i < 8; ++i) {
      int d = 0;
      ASSERT_EQ(::read(ch.report, &d, sizeof d), static_cast<ssize_t>(sizeof d));
      EXPECT_TRUE(all.insert(d).second) << "domain " << d << " leased twice";
    }
  }
  EXPECT_EQ(all.size(), 8u * 7u);
  // A child that exits gives its domains back: their lock files can be
  // locked again (another test could lease one in between; 48 of them all
  // at once would be a coincidence, not a lease that outlived its holder).
  const char go = 1;
  for (auto& ch : children) {
    ASSERT_EQ(::write(ch.hold, &go, 1), 1);
    int status = 0;
    ASSERT_EQ(::waitpid(ch.pid, &status, 0), ch.pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    ::close(ch.report);
    ::close(ch.hold);
  }
  int relockable = 0;
  const auto dir = std::filesystem::temp_directory_path() / "iplan-test-domains";
  for (int d : all) {
    if (mine.count(d)) continue;
    const int fd = ::open((dir / (std::to_string(d) + ".lock")).c_str(), O_RDWR | O_CLOEXEC);
    ASSERT_GE(fd, 0) << d;
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) ++relockable;
    ::close(fd);
  }
  EXPECT_GE(relockable, 47);
  // While held, the same file cannot be locked by another open file.
  const int fd = ::open((dir / (std::to_string(*mine.begin()) + ".lock")).c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  EXPECT_NE(::flock(fd, LOCK_EX | LOCK_NB), 0);
  ::close(fd);
}

}  // namespace
}  // namespace iplan::testing

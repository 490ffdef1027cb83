#include "iplan/core/atomic_file.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

namespace iplan::core {
namespace {

TEST(AtomicFile, ReplacesContentAndLeavesNoTemporary) {
  const auto dir = std::filesystem::temp_directory_path() / ("iplan-atomic-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "table.bin").string();
  WriteFileAtomically(path, "first");
  EXPECT_EQ(ReadFile(path), "first");
  WriteFileAtomically(path, std::string(100000, 'x'));
  EXPECT_EQ(ReadFile(path).size(), 100000u);
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1);
  std::filesystem::remove_all(dir);
}

TEST(AtomicFile, ErrorsNameThePath) {
  try {
    WriteFileAtomically("/nonexistent-dir/x.bin", "x");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.bin"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadFile("/nonexistent-dir/x.bin"), std::runtime_error);
}

// A pid that certainly names no running process: a child that has exited
// and been reaped (until the kernel hands the pid out again).
pid_t DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

TEST(AtomicFile, RemovesOnlyTheTemporariesOfDeadWriters) {
  const auto dir = std::filesystem::temp_directory_path() / ("iplan-stale-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "table.bin").string();
  const std::string dead = std::to_string(DeadPid());
  const std::vector<std::string> stale = {path + ".tmp." + dead};
  const std::vector<std::string> kept = {
      path,                                            // the file itself
      path + ".tmp." + std::to_string(getpid()),       // ours
      path + ".tmp." + std::to_string(getppid()),      // a running writer
      path + ".tmp.notapid",                           // not a name we make
      path + ".bak.tmp." + dead,                       // another file's
      (dir / "other.bin.tmp.").string() + dead,
  };
  for (const auto& f : stale) std::ofstream(f) << "half written";
  for (const auto& f : kept) std::ofstream(f) << "x";
  EXPECT_EQ(RemoveStaleTempFiles(path), stale);
  for (const auto& f : stale) EXPECT_FALSE(std::filesystem::exists(f)) << f;
  for (const auto& f : kept) EXPECT_TRUE(std::filesystem::exists(f)) << f;
  EXPECT_TRUE(RemoveStaleTempFiles(path).empty());  // nothing left to do
  EXPECT_TRUE(RemoveStaleTempFiles((dir / "missing" / "x.bin").string()).empty());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace iplan::core

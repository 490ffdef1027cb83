#include "iplan/core/atomic_file.h"

#include <unistd.h>

#include <filesystem>

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

}  // namespace
}  // namespace iplan::core

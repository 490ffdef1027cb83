// Where the multi-process tests find the executables they start, and the DDS
// domain each of them runs on.
#pragma once

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

#include "iplan/core/process.h"

namespace iplan::testing {

using core::Process;

/// build/bin/<name>.
inline std::string BinPath(const std::string& name) { return std::string(IPLAN_BIN_DIR) + "/" + name; }
/// The shipped configuration folder, config/ of the source tree.
inline const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config";
/// build/tests/<name>.
inline std::string TestBinPath(const std::string& name) { return std::string(IPLAN_BIN_DIR) + "/../tests/" + name; }

/// The DDS domain ids tests lease: 1..kLastTestDomain. Both vendors map a
/// domain to UDP ports 7400 + 250 * id + ..., so ids above 232 do not fit.
inline constexpr int kLastTestDomain = 230;

/// A DDS domain id that no other running test process holds, one per
/// distinct `offset` of this process (the same offset gives the same id), so
/// tests run in parallel without hearing each other. Each id is leased with
/// an exclusive flock(2) on `<tmp>/iplan-test-domains/<id>.lock`, held until
/// this process exits (the kernel releases it however the process ends, so a
/// crashed test never leaks a domain). The search starts at a point derived
/// from the pid and the offset, so two processes rarely contend for a lock.
/// A hash of the pid alone (this function's earlier form) gave two tests
/// running side by side the same domain about once in a suite run: the
/// depth chain test then heard another test's cell.
inline int UniqueDomain(int offset = 0) {
  static std::mutex mutex;
  static std::map<int, int> leased;  // offset -> domain id
  static pid_t holder = getpid();
  std::lock_guard lock(mutex);
  if (holder != getpid()) {  // a forked child leases its own
    leased.clear();
    holder = getpid();
  }
  if (auto it = leased.find(offset); it != leased.end()) return it->second;
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "iplan-test-domains";
  std::error_code ec;
  fs::create_directories(dir, ec);
  ::chmod(dir.c_str(), 01777);  // sticky and shared: any user's tests lease here
  const int start = static_cast<int>((static_cast<long>(getpid()) * 7 + offset) % kLastTestDomain);
  for (int k = 0; k < kLastTestDomain; ++k) {
    const int id = 1 + (start + k) % kLastTestDomain;
    bool taken = false;
    for (const auto& [o, d] : leased) taken |= d == id;
    if (taken) continue;
    const std::string path = (dir / (std::to_string(id) + ".lock")).string();
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) continue;
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      continue;
    }
    leased[offset] = id;  // fd stays open: the lease lasts as long as the process
    return id;
  }
  throw std::runtime_error("UniqueDomain: every DDS domain 1.." + std::to_string(kLastTestDomain) + " is leased by " +
                           dir.string() + "/*.lock holders");
}

/// A scratch folder `<tmp>/iplan-<name>-<pid>` holding a copy of the source
/// tree's `config/` as `config` without its learned state and trained
/// models, so a test runs a cell's configuration from scratch and may edit
/// it; removed with this object.
class ScratchCell {
 public:
  explicit ScratchCell(const std::string& name)
      : dir_(std::filesystem::temp_directory_path() / ("iplan-" + name + "-" + std::to_string(getpid()))) {
    namespace fs = std::filesystem;
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    fs::copy(fs::path(IPLAN_SOURCE_DIR) / "config", config(), fs::copy_options::recursive);
    fs::remove_all(config() / "state");
    fs::remove_all(config() / "models");
  }
  ~ScratchCell() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  ScratchCell(const ScratchCell&) = delete;
  ScratchCell& operator=(const ScratchCell&) = delete;

  const std::filesystem::path& dir() const { return dir_; }
  std::filesystem::path config() const { return dir_ / "config"; }

 private:
  std::filesystem::path dir_;
};

}  // namespace iplan::testing

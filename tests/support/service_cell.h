// A few services of the cell as real processes for a multi-process test:
// each started with the shipped configuration (config/) and the test's
// extra arguments, on one DDS vendor and a domain of the test's, with its
// log in a folder of its own (kept when the test failed). The test process
// plays whatever the cell lacks (a supervisor, a camera, trajopt).
#pragma once

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "iplan/dds/participant.h"
#include "test_paths.h"

namespace iplan::testing {

struct ServiceCell {
  ServiceCell(const std::string& tag, int domain, dds::Vendor vendor = dds::Vendor::kCyclone)
      : domain(domain), vendor(vendor) {
    dir = std::filesystem::temp_directory_path() / ("iplan-" + tag + "-" + std::to_string(getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~ServiceCell() {
    for (auto& [name, p] : procs) p->Signal(SIGTERM);
    for (auto& [name, p] : procs) p->Wait(std::chrono::seconds(10));
    if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
    else std::cout << "service logs kept in " << dir.string() << "\n";
  }
  /// Starts build/bin/`exe` with config/`cfg` and `extra` arguments.
  void Start(const std::string& exe, const std::string& cfg, const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {BinPath(exe), "--config", std::string(IPLAN_SOURCE_DIR) + "/config/" + cfg, "--dds",
                                     dds::ToString(vendor), "--domain", std::to_string(domain)};
    argv.insert(argv.end(), extra.begin(), extra.end());
    procs[exe] = std::make_unique<Process>(argv, std::map<std::string, std::string>{}, false, (dir / exe).string());
  }
  /// Stops every service; each must exit 0 on SIGTERM.
  void Stop() {
    for (auto& [name, p] : procs) p->Signal(SIGTERM);
    for (auto& [name, p] : procs) EXPECT_EQ(p->Wait(std::chrono::seconds(10)), 0) << name << ":\n" << p->Stderr();
    procs.clear();
  }
  int domain;
  dds::Vendor vendor;
  std::filesystem::path dir;
  std::map<std::string, std::unique_ptr<Process>> procs;
};

}  // namespace iplan::testing

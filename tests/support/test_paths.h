// Where the multi-process tests find the executables they start.
#pragma once

#include <unistd.h>

#include <string>

#include "iplan/core/process.h"

namespace iplan::testing {

using core::Process;

/// build/bin/<name>.
inline std::string BinPath(const std::string& name) { return std::string(IPLAN_BIN_DIR) + "/" + name; }
/// build/tests/<name>.
inline std::string TestBinPath(const std::string& name) { return std::string(IPLAN_BIN_DIR) + "/../tests/" + name; }
/// A DDS domain id unique to this test process (from the pid), so tests can
/// run in parallel without hearing each other.
inline int UniqueDomain(int offset = 0) { return 1 + static_cast<int>((getpid() * 7 + offset) % 200); }

}  // namespace iplan::testing

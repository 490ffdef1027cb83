// The `iplan` command-line tool is assembled from subcommand files
// (tools/iplan/cmd_*.cc). Each file registers itself at static-initialisation
// time, so adding a subcommand never touches main.cc.
//
//   namespace {
//   const bool kRegistered = iplan::cli::RegisterCommand(
//       "collision-bound", [](CLI::App& app) { ... add subcommand ... });
//   }
//
// The registration callback adds a subcommand to `app` (with options and a
// callback that does the work). The callback of a subcommand reports its exit
// code through iplan::cli::SetExitCode.
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace iplan::cli {

using RegisterFn = std::function<void(CLI::App&)>;

/// Adds a subcommand family. `order_key` only sorts the --help listing.
/// Thread-safety: static initialisation only.
bool RegisterCommand(const std::string& order_key, RegisterFn fn);

/// Sets the process exit code returned by main() after the subcommand ran.
void SetExitCode(int code);

}  // namespace iplan::cli

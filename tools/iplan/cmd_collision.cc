// `iplan collision-bound`: the collision bound of METHOD 4 for JSON lines on
// stdin (see collision_bound_cli.h for the format).
#include <iostream>

#include "command_registry.h"
#include "collision_bound_cli.h"

namespace {

const bool kRegistered = iplan::cli::RegisterCommand("collision-bound", [](CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "collision-bound",
      "Probabilistic collision bound for robot/human sphere pairs.\n"
      "Reads JSON lines from stdin: {\"b\":[x,y,z],\"r_robot\":r1,\"mu\":[x,y,z],"
      "\"sigma\":[9 numbers, row-major],\"r_human\":r2} (m, m^2)\n"
      "and writes one line per input: {\"bound\":p,\"x_max\":[x,y,z],\"lambda\":l} or "
      "{\"error\":\"line N: ...\"}.\nExit code 1 if any line failed.");
  cmd->callback([] {
    const int failures = iplan::collision::RunCollisionBoundJsonLines(std::cin, std::cout);
    iplan::cli::SetExitCode(failures > 0 ? 1 : 0);
  });
});

}  // namespace

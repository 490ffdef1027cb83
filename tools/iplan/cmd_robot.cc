// `iplan robot spheres`: the sphere cover of a robot's collision geometry
// (robot_spheres_cli.h).
#include <iostream>

#include "command_registry.h"
#include "robot_spheres_cli.h"

namespace {

const bool kRegistered = iplan::cli::RegisterCommand("robot", [](CLI::App& app) {
  CLI::App* robot = app.add_subcommand("robot", "Robot descriptions: what the cell's checks see of an arm");
  robot->require_subcommand(1);
  auto opts = std::make_shared<iplan::collision::RobotSpheresOptions>();
  CLI::App* spheres = robot->add_subcommand(
      "spheres",
      "Cover the robot's collision geometry (primitives and STL/DAE/OBJ meshes) with spheres, as every service "
      "does when it loads the robot, and print per link the sphere count, uncovered_vertices (0: every mesh "
      "vertex is inside a sphere) and max_excess_m (how far the spheres may reach beyond the geometry, m). Mesh "
      "covers are cached by mesh hash ($IPLAN_CACHE_DIR, $XDG_CACHE_HOME/iplan or ~/.cache/iplan, under "
      "spheres/), where the services and the viewer find them. Exit 0 when everything is covered, 1 when not, "
      "2 on bad input. docs/robots.md.");
  spheres->add_option("robot", opts->robot, "a URDF, a URDF overlay or a DH YAML")->required();
  spheres->add_flag("--json", opts->json, "one JSON document (fields in docs/robots.md)");
  spheres->add_option("--out", opts->out, "also write the spheres (link frames) to this JSON file");
  spheres->add_option("--max-excess", opts->max_excess, "m; how far a mesh's spheres may reach beyond it (default 0.025)")
      ->check(CLI::Range(0.002, 0.2));
  spheres->add_flag("--no-cache", opts->no_cache, "compute every mesh cover; read and write no cache");
  spheres->callback([opts] { iplan::cli::SetExitCode(iplan::collision::RunRobotSpheres(*opts, std::cout, std::cerr)); });
});

}  // namespace

// `iplan plan`: one-shot trajectory planning (logic in plan_cli.h).
#include <cstdint>
#include <iostream>

#include "command_registry.h"
#include "plan_cli.h"

namespace {

const bool kRegistered = iplan::cli::RegisterCommand("plan", [](CLI::App& app) {
  auto opts = std::make_shared<iplan::planning::PlanCliOptions>();
  auto threads = std::make_shared<int>(-1);
  auto seed = std::make_shared<std::int64_t>(-1);
  CLI::App* cmd = app.add_subcommand(
      "plan",
      "Plan a joint trajectory (ITOMP-style optimisation, docs/planning.md).\n"
      "Exit code 0 on success, 1 when no safe feasible trajectory was found, 2 on bad input.");
  cmd->add_option("--scene", opts->scene, "scene YAML (config/scenes/cell.yaml)")->required();
  cmd->add_option("--robot", opts->robot, "robot: a DH YAML, a URDF or a URDF overlay (docs/robots.md)")
      ->capture_default_str();
  cmd->add_option("--config", opts->config, "planner params YAML (config/planner.yaml)");
  cmd->add_option("--start", opts->start, "start joint positions, one per joint of the robot (rad or m)")
      ->delimiter(',')->required();
  auto* g = cmd->add_option("--goal", opts->goal, "goal joint positions, one per joint (rad or m)")->delimiter(',');
  auto* gp = cmd->add_option("--goal-pose", opts->goal_pose,
                             "goal end-effector pose x,y,z,qx,qy,qz,qw (m, unit quaternion)")
                 ->delimiter(',');
  g->excludes(gp);
  cmd->add_option("--tool-link", opts->tool_link,
                  "link whose pose --goal-pose gives (default: the config's end_effector_link; without a config, "
                  "panda_link8, or the robot's last link when it has no such link)");
  cmd->add_option("--prediction", opts->prediction, "human prediction JSON (docs/planning.md)");
  cmd->add_option("--human", opts->human, "human body YAML (default: built-in upper body)");
  cmd->add_option("--threads", *threads, "worker threads (default: params)");
  cmd->add_option("--seed", *seed, "random seed (default: params)");
  cmd->add_flag("--json", opts->json, "print one JSON line");
  cmd->callback([opts, threads, seed] {
    if (*threads >= 0) opts->threads = *threads;
    if (*seed >= 0) opts->seed = static_cast<std::uint64_t>(*seed);
    iplan::cli::SetExitCode(iplan::planning::RunPlanCommand(*opts, std::cout, std::cerr));
  });
});

}  // namespace

// `iplan cell-check`: does the cell's geometry agree with its task graph?
//
// The task graph declares which robot tasks conflict with which human
// actions; the supervisor's reward and the learned task order rest on those
// declarations. This command puts the robot at every task's goal (and
// retreat, which must be harmless during every action), lets the
// configured synthetic person do every action (several repetitions, with the
// configured variation and sensor noise), and runs the collision-risk
// service's own ISO/TS 15066 monitor on it. A task the graph calls harmless
// that the monitor would stop is an inconsistency: the robot would wait there
// whatever the task planner learns. Each goal's clearance from the static
// scene is checked against the trajectory optimiser's minimum too: a goal
// inside an obstacle fails every time it is commanded. Offline, no DDS.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>

#include "command_registry.h"
#include "services/perception/core/synthetic_person.h"
#include "services/supervisor/core/task_goals.h"
#include "services/supervisor/core/task_planner.h"
#include "iplan/framework/config.h"
#include "iplan/framework/service.h"
#include "iplan/framework/service_file.h"
#include "iplan/planning/planner.h"
#include "services/collision_risk/risk_config.h"
#include "services/perception/perception_settings.h"
#include "services/supervisor/core/supervisor_settings.h"
#include "services/trajopt/trajopt_config.h"

namespace iplan::cli {
namespace {

namespace fs = std::filesystem;

struct CheckOptions {
  std::string config_dir;
  std::string robot;  // another arm; empty: the configured
  double margin = 0.05;  // m, clearance required beyond S_p for harmless pairs
  int repetitions = 5;
};

// Worst moment of one (task, action) pair.
struct PairResult {
  double margin = std::numeric_limits<double>::infinity();  // separation - S_p, m
  double separation = 0, protective = 0, human_speed = 0, time = 0;
  std::string robot_link, human_segment;
};

std::string Fixed(double v, int digits, bool sign = false) {
  std::ostringstream s;
  if (sign) s << std::showpos;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

// The monitor's view while the person does `action` (repeated, each
// repetition with its own variation) and the robot rests at `goal`.
// `fresh` is a monitor that has seen nothing yet; it is copied, so the models
// are loaded once for all pairs.
PairResult Evaluate(const collision_risk::RiskMonitor& fresh, const collision_risk::RiskParams& params,
                    const perception::SyntheticPersonParams& person_params, const std::string& action,
                    const std::vector<double>& goal, int repetitions) {
  perception::SyntheticPersonParams p = person_params;
  const auto it = std::find_if(p.actions.begin(), p.actions.end(), [&](const auto& a) { return a.name == action; });
  const double period = it->period;
  p.script = {perception::ScriptStep{action, 2 * period}};
  p.loop = false;
  perception::SyntheticPerson person(p);
  collision_risk::RiskMonitor monitor = fresh;
  const std::vector<std::string> robot_joints = monitor.robot().JointNames();
  if (goal.size() != robot_joints.size()) {
    throw std::runtime_error("goal has " + std::to_string(goal.size()) + " joints, the robot " +
                             std::to_string(robot_joints.size()));
  }
  PairResult worst;
  const double dt = 1.0 / 30;
  const double length = 2 * period;
  for (int rep = 0; rep < repetitions; ++rep) {
    const double start = rep * (length + 1.0);
    person.StartScript(start);
    // Skip the first speed window: the monitor uses the ISO default speed
    // until it has seen enough skeletons, which is not the action's speed.
    const double settle = params.ssm.speed_window;
    for (double t = start; t < start + length; t += dt) {
      const auto stamp = static_cast<int64_t>(std::llround(t * 1e9));
      monitor.UpdateRobotState(stamp, robot_joints, goal);
      std::vector<std::string> names;
      std::vector<Eigen::Vector3d> pos;
      for (const auto& j : person.Observe(t)) {
        names.push_back(j.name);
        pos.push_back(j.position_W);
      }
      if (auto why = monitor.UpdateSkeleton(stamp, names, pos)) throw std::runtime_error(*why);
      if (t < start + settle) continue;
      const collision_risk::RiskReport r = monitor.Evaluate(stamp);
      if (!r.separation_margin) throw std::runtime_error("the monitor saw no person while checking " + action);
      const double m = *r.separation_margin;
      if (m < worst.margin) {
        worst.margin = m;
        worst.separation = *r.binding_separation;
        worst.protective = r.protective_separation;
        worst.human_speed = r.human_speed;
        worst.time = t - start;
        worst.robot_link = r.binding_robot_link;
        worst.human_segment = r.binding_human_segment;
      }
    }
  }
  return worst;
}

// What the check reads from the cell's configuration folder.
struct CellInputs {
  perception::SyntheticPersonParams person;
  collision_risk::RiskConfig risk;
  supervisor::TaskGraph graph;
  std::unique_ptr<planning::Planner> planner;
  std::optional<collision_risk::RiskMonitor> monitor;
};

// Every file is read as its service reads it (framework::ServiceFile): the
// same keys, defaults and checks. Throws std::runtime_error (ConfigError).
void LoadCellInputs(const std::string& dir, const std::string& robot, CellInputs* in) {
  perception::PerceptionSettings perception;
  framework::ServiceFile(framework::CellFile(dir, "perception")).ReadSection("perception", &perception).Finish();
  in->person = perception.synthetic.Person();
  in->risk = collision_risk::LoadRiskConfig(framework::CellFile(dir, "collision_risk"), robot);
  // The check asks about the working cell, where predictions flow: the
  // separation layer with the person's measured speed, not the degraded
  // mode the monitor falls back to when intent is gone.
  in->risk.params.ssm.degrade_without_prediction = false;
  in->monitor = collision_risk::MakeRiskMonitor(in->risk);
  framework::ServiceFile sconf(framework::CellFile(dir, "supervisor"));
  supervisor::SupervisorSettings supervisor;
  sconf.ReadSection("supervisor", &supervisor).Finish();
  in->graph = supervisor::LoadTaskGraph(sconf.ResolvePath(supervisor.task_graph));
  // The static scene, as the trajectory optimiser sees it.
  in->planner = trajopt::MakePlanner(trajopt::LoadTrajoptConfig(framework::CellFile(dir, "trajopt"), robot));
  for (const std::string& note : supervisor::ResolveTaskGoals(*in->planner, &in->graph)) std::cout << note << "\n";
}

// One row per place the robot rests at: every task's goal and, for tasks
// with one, the retreat it withdraws to (where it waits for the next task,
// so it must be harmless during every action).
struct Row {
  std::string name;
  const std::vector<double>* pose;
  std::vector<std::string> conflicts_with;
  bool retreat;
};

// One cell of the table: the margin printed, and what it means for the
// graph (a problem when a harmless task or a retreat is not clear, a note
// when a declared conflict stays clear).
void JudgePair(const Row& task, const std::string& action, const PairResult& r, double margin,
               std::vector<std::string>* problems, std::vector<std::string>* notes) {
  const bool declared =
      std::find(task.conflicts_with.begin(), task.conflicts_with.end(), action) != task.conflicts_with.end();
  std::cout << std::right << std::setw(static_cast<int>(std::max<std::size_t>(action.size(), 8) + 2))
            << Fixed(r.margin, 2, true) << (declared ? "*" : " ");
  const std::string detail = "separation " + Fixed(r.separation, 2) + " m (" + r.robot_link + " / " + r.human_segment +
                             "), S_p " + Fixed(r.protective, 2) + " m at v_h " + Fixed(r.human_speed, 2) + " m/s, " +
                             Fixed(r.time, 1) + " s into the action";
  if (!declared && r.margin < margin) {
    const std::string within =
        " the person comes within " +
        std::string(r.margin < 0 ? "the protective separation: the monitor would stop the robot there ("
                                 : "the required margin of it (") +
        detail;
    problems->push_back(task.retreat ? "'" + task.name + "': during '" + action + "'" + within +
                                           "). A retreat must be clear of every action: move it out of the "
                                           "person's space."
                                     : "'" + task.name + "' is declared harmless during '" + action + "' but" + within +
                                           "). Declare conflicts_with: [" + action + "] or move the goal.");
  } else if (declared && r.margin >= margin) {
    notes->push_back("'" + task.name + "' is declared to conflict with '" + action + "' but stays clear (" + detail +
                     "); only the reward's harmony term keeps them apart.");
  }
}

int RunCellCheck(const CheckOptions& o) {
  const std::string dir = o.config_dir.empty() ? framework::DefaultConfigDir() : o.config_dir;
  if (dir.empty()) {
    std::cerr << "iplan cell-check: no configuration found (set --config-dir or $IPLAN_CONFIG_DIR)\n";
    return 2;
  }
  CellInputs in;
  try {
    LoadCellInputs(dir, o.robot.empty() ? "" : fs::absolute(o.robot).string(), &in);
  } catch (const std::exception& e) {
    std::cerr << "iplan cell-check: " << e.what() << "\n";
    return 2;
  }
  // The graph's human actions must be actions the person can do.
  std::vector<std::string> problems, notes, actions;
  for (const auto& a : in.graph.human_actions) {
    if (std::any_of(in.person.actions.begin(), in.person.actions.end(), [&](const auto& m) { return m.name == a; })) {
      actions.push_back(a);
    } else {
      problems.push_back("human action '" + a + "' of the task graph is not an action of the synthetic person (perception.yaml)");
    }
  }
  const double min_clearance = in.planner->params().min_clearance;
  std::cout << "ISO/TS 15066 margin (separation - protective separation, m) with the robot at each task's goal\n"
            << "and retreat and the person doing each action (worst of " << o.repetitions
            << " repetitions, sensor noise included;\n* = declared conflict), and the pose's clearance from "
            << "the static scene (m; the trajectory optimiser\nneeds at least " << Fixed(min_clearance, 3) << "):\n\n";
  std::vector<Row> rows;
  for (const auto& t : in.graph.tasks) {
    rows.push_back({t.name, &t.goal, t.conflicts_with, false});
    if (!t.retreat.empty()) rows.push_back({t.name + " (retreat)", &t.retreat, {}, true});
  }
  std::size_t w = 6;
  for (const auto& r : rows) w = std::max(w, r.name.size() + 2);
  std::cout << std::left << std::setw(static_cast<int>(w)) << "task";
  for (const auto& a : actions) std::cout << std::right << std::setw(static_cast<int>(std::max<std::size_t>(a.size(), 8) + 3)) << a;
  std::cout << std::right << std::setw(12) << "clearance" << "\n";
  for (const Row& task : rows) {
    std::cout << std::left << std::setw(static_cast<int>(w)) << task.name;
    for (const auto& a : actions) {
      try {
        JudgePair(task, a, Evaluate(*in.monitor, in.risk.params, in.person, a, *task.pose, o.repetitions), o.margin,
                  &problems, &notes);
      } catch (const std::exception& e) {
        std::cerr << "\niplan cell-check: task '" << task.name << "': " << e.what() << "\n";
        return 2;
      }
    }
    const double clearance = in.planner->CalcClearance(
        Eigen::Map<const Eigen::VectorXd>(task.pose->data(), static_cast<Eigen::Index>(task.pose->size())));
    std::cout << std::right << std::setw(11) << Fixed(clearance, 3) << "\n";
    if (clearance < min_clearance) {
      problems.push_back("'" + task.name + "' rests in the static scene (clearance " + Fixed(clearance, 3) + " m < " +
                         Fixed(min_clearance, 3) + " m): the trajectory optimiser will refuse it every time.");
    }
  }
  std::cout << "\n";
  for (const auto& n : notes) std::cout << "note: " << n << "\n";
  for (const auto& p : problems) std::cout << "inconsistent: " << p << "\n";
  if (problems.empty()) {
    std::cout << "consistent: every task the graph calls harmless keeps at least " << Fixed(o.margin, 2)
              << " m beyond S_p\n";
  }
  return problems.empty() ? 0 : 1;
}

const bool kRegistered = RegisterCommand("cell-check", [](CLI::App& app) {
  auto o = std::make_shared<CheckOptions>();
  CLI::App* c = app.add_subcommand(
      "cell-check",
      "Check that the cell's geometry agrees with its task graph: with the robot at each task's goal and\n"
      "retreat and the synthetic person doing each human action, the ISO/TS 15066 monitor (collision_risk.yaml)\n"
      "must not stop the robot for tasks the graph calls harmless, nor at any retreat. Prints the margin table;\n"
      "exit code 0 when consistent, 1 when not, 2 on bad configuration. Resting poses only: paths between them\n"
      "are not checked.");
  c->add_option("--config-dir", o->config_dir, "configuration folder (default: $IPLAN_CONFIG_DIR, installed, or source)");
  c->add_option("--robot", o->robot,
                "check the cell with another arm: a URDF or URDF overlay (docs/robots.md); the task graph's "
                "poses are solved for it")
      ->check(CLI::ExistingFile);
  c->add_option("--margin", o->margin, "m of clearance beyond S_p required for harmless pairs")->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  c->add_option("--repetitions", o->repetitions, "repetitions of each action (each with its own variation)")
      ->capture_default_str()->check(CLI::Range(1, 100));
  c->callback([o] { SetExitCode(RunCellCheck(*o)); });
});

}  // namespace
}  // namespace iplan::cli

// Reads the cell's configuration folder (the services' own files) into what
// the one-process cell simulation needs, with each service's readers:
//   trajopt.yaml         robot, human body, scene, replanning planner, replanner
//   collision_risk.yaml  the monitor and its evaluation rate
//   robot_sim.yaml       control and joint-state rates, stopping time, contact margin
//   supervisor.yaml      task graph, resume delay
//   perception.yaml      sensor rate, the synthetic person (and its sensor noise)
//   intent.yaml          the estimator's settings (the model itself: EnsureCellModel)
// Only the keys used here are read; the rest are the services' business, but
// a key read here with a bad value is an error.
#pragma once

#include <memory>
#include <string>

#include "tools/cell_sim/core/cell_benchmark.h"
#include "tools/cell_sim/core/interaction_benchmark.h"
#include "iplan/planning/planner.h"

namespace iplan::cell_sim {

struct CellConfig {
  std::string dir;  ///< the configuration folder
  std::unique_ptr<planning::Planner> planner;
  std::unique_ptr<collision::HumanBodyModel> body;
  std::unique_ptr<collision_risk::RiskMonitor> monitor;
  trajopt::ReplannerParams replanner;
  robot_sim::SimulatorParams simulator;
  LoopParams loop;  ///< rates and resume delay from the files; the rest defaults
  intent_service::IntentEstimatorParams estimator;
  perception::SyntheticPersonParams person;
  double sensor_rate_hz = 30;
  double sensor_noise_std = 0.01;
  std::vector<GraphTask> tasks;
  /// The task graph as the supervisor loads it, its places resolved for the
  /// robot (joint goals), with the person's human_graph.
  supervisor::TaskGraph graph;
  supervisor::QLearningParams learning;  ///< supervisor.yaml's Q-learning and anticipation parameters
  supervisor::ActionTrackerParams tracker;  ///< supervisor.yaml's: how the model's belief dates its action
  double pause_between_tasks = 0.5;      ///< s, supervisor.yaml
  /// Places of the task graph whose joint positions were not used as
  /// written (supervisor::ResolveTaskGoals), for the tool to print.
  std::vector<std::string> goal_notes;

  /// A setup whose model pointers point into this object (which must
  /// outlive it); intent model, recordings and benchmark options are the
  /// caller's to fill in.
  BenchmarkSetup MakeSetup() const;
  /// The same for the episode benchmark (`iplan eval cell`).
  CellBenchmarkSetup MakeCellSetup() const;
};

/// Loads `dir`. `planner_threads` (>= 0; 0: the file's) replaces the
/// planner's thread count, which changes no result (Planner::Plan is
/// bit-identical for any thread count). Throws std::runtime_error naming the
/// file and key on a bad configuration. A non-empty `robot_file` replaces
/// the robot of the trajectory optimiser and collision risk (another arm,
/// `--robot`); the task graph's poses are solved for it.
CellConfig LoadCellConfig(const std::string& dir, int planner_threads, const std::string& robot_file = "");

}  // namespace iplan::cell_sim

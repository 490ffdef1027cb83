// The closed-loop interaction benchmark behind `iplan eval interaction`:
// seeded scenarios in the cell (a robot task while a person moves near or
// across its path), each run once per predictor with RunInteraction, and
// the per-predictor figures over the scenarios.
//
// Two suites of scenarios (Suite). The default one alternates, in blocks of
// four, between
//   task:   a task of the task graph (to its goal, with its retreat) from
//           another of the graph's poses, or a table-top reach (a flange
//           pose over the table, solved by the planner's IK) from one;
//   person: recorded arm motion (the recordings' subjects in turn, a random
//           sequence, clip start, placement across the table and start
//           delay) or the cell's synthetic person (moved, turned, its script
//           starting at a random time).
// Many of its scenarios never bring the person near the robot's path. In the
// shared-space suite sharing space is the point: scenario i is of kind i % 4
//   hand-over:   the graph's hand_over task while the person reaches towards
//                the hand-over place (just in front of and below the flange
//                at the task's goal);
//   parts-bin:   fetch_left (over the parts bin) while the person reaches
//                into the bin or between it and their parts tray;
//   co-assembly: a reach to a flange point at the robot's side of the
//                person's assembly area while the person assembles just
//                beyond it;
//   crossing:    a graph task while the person's hand sweeps across the
//                robot's path (through its point nearest the person) in the
//                middle of the task;
// with the synthetic person in scenarios 0-3 of every 8 (their own actions
// with the targets above, or a HandSweep) and recorded motion in 4-7 (the
// recording placed so that its hands' farthest reach towards the robot in
// the task's first SharedSpaceParams::window s falls 0.10-0.25 m beyond
// the scenario's shared point, the shoulders no nearer the robot than
// x = 1.0 m; a seated person's hands stay near their farthest reach much of
// the time, and on the shared point they would hold the robot's goal for
// good). Every scenario is checked before it
// is run: its PathDistance (the person's true body over
// SharedSpaceParams::window s from the task command against the robot's
// spheres on the straight joint path from start to goal) must be below
// SharedSpaceParams::max_path_distance; a draw that is not is drawn again,
// from the scenario's own stream.
// Everything drawn is a function of the benchmark seed, the suite and the
// scenario index; the person, their sensor noise and the model's predictions
// are the same for every predictor of a scenario (paired comparison).
//
// Predictors (what the trajectory optimiser plans against):
//   none               no prediction (the planner knows only its own path);
//   constant-position  / constant-velocity: iplan::intent baselines, at the
//                      model's rate and horizon;
//   model              the trained intent model through the intent service's
//                      estimator (window, belief filter), as in the cell;
//   oracle             the true future motion at the model's steps, with the
//                      model's covariances (the within-action part, sum_c p_c
//                      Sigma_c): the limit of what prediction can give;
//   oracle-action      (iplan eval cell only, cell_benchmark.h) as oracle, but
//                      the person's current action's motion as if it went on
//                      for ever: what a per-action forecaster with a perfect
//                      recogniser could give, not knowing when an action
//                      ends.
// The collision-risk monitor gets the same prediction as the planner, as the
// cell's one prediction topic would carry it (MonitorInput::kSame, the
// default); with `none` it gets the model's: the cell's intent service still
// runs, only the planner ignores it (the monitor's degraded mode, v_h = 1.6
// m/s whenever the person is seen, would stop this cell's robot whenever it
// is within about 0.8 m of the person, which measures the ISO default
// rather than planning). MonitorInput::kModel gives the monitor the model's
// prediction for every predictor, holding the safety layer fixed so that
// only planning differs.
//
// Units: m, rad, s; world frame W. Not thread-safe (one owner); allocates.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "services/intent/core/intent_estimator.h"
#include "tools/cell_sim/core/interaction_loop.h"
#include "tools/cell_sim/core/person_motion.h"
#include "services/perception/core/synthetic_person.h"
#include "iplan/intent/baseline_predictors.h"
#include "iplan/intent/intent_model.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::cell_sim {

/// An intent core's prediction `m` as one of the observation at t0_ns (ns,
/// simulated time), its joints named `joints`.
collision::JointMixture Stamped(collision::JointMixture m, const std::vector<std::string>& joints, int64_t t0_ns);

enum class Predictor { kNone, kConstantPosition, kConstantVelocity, kModel, kOracle, kOracleAction };

/// "none", "constant-position", "constant-velocity", "model", "oracle",
/// "oracle-action".
const char* ToString(Predictor p);
/// The predictor named `name` (as ToString), or nullopt.
std::optional<Predictor> ParsePredictor(const std::string& name);
/// Every predictor name, in the order above.
std::vector<std::string> PredictorNames();

/// Which scenarios MakeScenarios draws (see the top of this file).
enum class Suite {
  kDefault,      ///< "default": tasks and table-top reaches, the person near or across the path
  kSharedSpace,  ///< "shared-space": hand-over, parts bin, co-assembly, crossing; the person always within reach
};

/// "default", "shared-space".
const char* ToString(Suite s);
/// The suite named `name` (as ToString), or nullopt.
std::optional<Suite> ParseSuite(const std::string& name);
/// Every suite name, default first.
std::vector<std::string> SuiteNames();

/// The shared-space suite's kinds, in the order its scenarios take them
/// (scenario i is of kind i % 4): "hand-over", "parts-bin", "co-assembly",
/// "crossing".
const std::vector<std::string>& SharedSpaceKinds();

/// How near the shared-space suite's person must come to the robot's path.
struct SharedSpaceParams {
  /// m: a scenario is kept only when its PathDistance is below this
  /// (surface distance; 0.35 m is well inside the cell's protective
  /// separation distance for a person reaching at 1 m/s).
  double max_path_distance = 0.35;
  double window = 5.0;    ///< s from the task command over which the person's true body counts
  int path_samples = 21;  ///< configurations on the straight joint path from start to goal, both ends included (>= 2)
  int max_draws = 100;    ///< draws per scenario before MakeScenarios gives up (>= 1)
  /// Empty when valid, else the offending field and value.
  std::string Validate() const;
};

enum class MonitorInput {
  kSame,   ///< the monitor gets the planner's prediction (none: the model's)
  kModel,  ///< the monitor always gets the model's prediction
};

/// A task of the cell's task graph.
struct GraphTask {
  std::string name;
  Eigen::VectorXd goal;     ///< rad, model joint order
  Eigen::VectorXd retreat;  ///< rad; empty: none
};

/// Default baseline parameters of `kind`.
inline intent::BaselinePredictorParams Baseline(intent::BaselineKind kind) {
  intent::BaselinePredictorParams p;
  p.kind = kind;
  return p;
}

/// Everything the scenarios are made of. Pointers are not owned.
struct BenchmarkSetup {
  CellModels models;
  LoopParams loop;
  std::shared_ptr<const intent::IntentModel> intent_model;  ///< the cell's trained model
  intent_service::IntentEstimatorParams estimator;
  /// Baselines; their rate and horizon are replaced by the model's.
  intent::BaselinePredictorParams constant_position = Baseline(intent::BaselineKind::kConstantPosition);
  intent::BaselinePredictorParams constant_velocity = Baseline(intent::BaselineKind::kConstantVelocity);
  const intent::SkeletonDataset* recordings = nullptr;  ///< recorded motion (e.g. assembly.csv)
  std::string recordings_file;                          ///< its path, for messages and the report
  std::map<std::string, std::string> joint_map;         ///< recording joint -> body joint (perception.replay.joint_map)
  perception::SyntheticPersonParams person;             ///< the cell's synthetic person
  double sensor_rate_hz = 30;                           ///< skeletons per second
  double sensor_noise_std = 0.01;                       ///< m per coordinate
  std::vector<GraphTask> tasks;                         ///< the task graph's tasks
  double time_limit = 20;                               ///< s per task (the replanner fails it after)
  MonitorInput monitor_input = MonitorInput::kSame;
  SharedSpaceParams shared_space;  ///< the shared-space suite's proximity requirement
  /// Empty when usable, else why not (missing models, no recordings, a graph
  /// with fewer than two poses, invalid baseline params, ...).
  std::string Validate() const;
};

/// One scenario: how it was built (everything needed to run it again).
struct ScenarioSpec {
  int index = 0;
  uint64_t seed = 0;            ///< of this scenario's sensor noise
  std::string source;           ///< "recorded" or "synthetic"
  std::string subject;          ///< recorded: the recording's subject; synthetic: "synthetic"
  std::string sequence;         ///< recorded: sequence id; synthetic: the script's actions, comma-separated
  Eigen::Vector3d placement_W = Eigen::Vector3d::Zero();  ///< m: recorded: shoulder centre; synthetic: torso
  double yaw = 0;               ///< rad, turned from facing the robot
  double clip_start = 0;        ///< s into the recording (recorded only)
  /// s after the scenario start at which the person's motion starts
  /// (recorded: the clip, its first pose held before; synthetic: the script,
  /// negative when already under way). The task is commanded at
  /// LoopParams::task_start.
  double delay = 0;
  std::string task;             ///< the graph task's name, or "reach"
  std::string start;            ///< name of the start pose (a graph task's goal or "<task>.retreat")
  Eigen::VectorXd start_q, goal_q, retreat_q;  ///< rad; retreat_q empty: none
  Eigen::Vector3d reach_p_WE = Eigen::Vector3d::Zero();  ///< m, reach only: the flange target

  // The shared-space suite only (empty / none in the default suite).
  std::string kind;  ///< one of SharedSpaceKinds()
  /// Synthetic person: actions that replace the cell's of the same name or
  /// are added to them (targets moved to the shared point), and the script
  /// (empty: the cell's).
  std::vector<perception::ActionMotion> person_actions;
  std::vector<perception::ScriptStep> person_script;
  std::optional<HandSweep> sweep;  ///< synthetic: the hand sweeping across the robot's path (crossing)
  /// m, W: where robot and person meet by design: the person's reach target
  /// (hand-over, parts-bin), the robot's reach target (co-assembly), the
  /// path's point nearest the person that the hand sweeps through (crossing).
  Eigen::Vector3d shared_point_W = Eigen::Vector3d::Zero();
  std::optional<double> path_distance;  ///< m: ScenarioPathDistance, below SharedSpaceParams::max_path_distance
  int draws = 0;  ///< draws it took (the ones before were too far from the path, or not reachable)
};

/// Sets the baselines' rate and horizon to the intent model's and fits their
/// per-joint covariance growth (intent::CalibrateBaselineGrowth, body joints)
/// to their own errors on `demonstrations`: for the cell, the synthetic
/// person's demonstrations the model is trained on, so that baselines and
/// model learn their uncertainty from the same data. Throws
/// std::invalid_argument when setup has no model or the data lacks a joint.
void CalibrateBaselines(const intent::SkeletonDataset& demonstrations, BenchmarkSetup* setup);

/// Draws `count` scenarios (>= 1) of `suite` from `seed` (scenario k is the
/// same whatever the count). Throws std::invalid_argument on an unusable
/// setup (shared-space: also without the task graph's hand_over and
/// fetch_left tasks or the synthetic person's reach_parts (reach) and
/// assemble (work) actions, or with invalid SharedSpaceParams), or
/// std::runtime_error when no reachable table-top pose is found (default)
/// or no draw of SharedSpaceParams::max_draws brings the person near enough
/// (shared-space, naming the scenario and the nearest distance drawn).
std::vector<ScenarioSpec> MakeScenarios(const BenchmarkSetup& setup, int count, uint64_t seed,
                                        Suite suite = Suite::kDefault);

/// Smallest surface distance (m; negative: overlapping) between the
/// person's true body spheres (`body`; every frame of `person` stamped in
/// [t0, t1] s) and the robot's collision spheres at `samples` (>= 2)
/// configurations evenly along the straight joint-space path from start_q
/// to goal_q (rad, model order, size robot.nq; both ends included): the
/// measure of the true separation (RobotSimulator::UpdateContacts), taken
/// before any planning, of how near the person comes to where the robot is
/// going. Throws std::invalid_argument on wrong sizes, samples < 2, a
/// person whose joints are not the body's, or no frame in [t0, t1].
/// Thread-safe; allocates.
double PathDistance(const collision::RobotModel& robot, const collision::HumanBodyModel& body,
                    const Eigen::VectorXd& start_q, const Eigen::VectorXd& goal_q, int samples,
                    const PersonStream& person, double t0, double t1);

/// The PathDistance by which MakeScenarios judges `spec`: its person (the
/// truth of the stream RunScenario plays), from the task command
/// (LoopParams::task_start) for SharedSpaceParams::window s, against the
/// path from start_q to goal_q with SharedSpaceParams::path_samples
/// configurations. Throws as PathDistance and the person's stream.
double ScenarioPathDistance(const BenchmarkSetup& setup, const ScenarioSpec& spec);

/// Runs `spec` once per predictor (results in that order). Throws as
/// RunInteraction, and std::invalid_argument when the model's joints are not
/// the body's.
std::vector<InteractionResult> RunScenario(const BenchmarkSetup& setup, const ScenarioSpec& spec,
                                           const std::vector<Predictor>& predictors);

/// Median and [p10, p90] (nearest rank) of a set of values; zeros when empty.
struct Spread {
  double median = 0, p10 = 0, p90 = 0;
};
Spread SpreadOf(std::vector<double> values);

/// One predictor's figures over the scenarios.
struct PredictorSummary {
  Predictor predictor = Predictor::kNone;
  int scenarios = 0;
  int succeeded = 0;            ///< tasks that arrived (the rest failed or ran out of time)
  Spread task_time;             ///< s (failed tasks count with their time when they ended)
  Spread protective_stops;
  int protective_stops_total = 0;
  int stops_separation_total = 0;  ///< started by the ISO/TS 15066 separation layer
  int stops_bound_total = 0;       ///< started by the collision bound
  Spread stop_time;             ///< s
  double stop_time_total = 0;   ///< s
  int slow_downs_total = 0;     ///< times the monitor slowed the robot (speed reduction)
  double slow_time_total = 0;   ///< s the robot ran slowed down
  Spread min_separation;        ///< m
  Spread max_bound;
  int true_contacts = 0;
  int robot_moving_contacts = 0;   ///< of true_contacts, the robot faster than kMovingContactSpeed at the first moment
  int robot_at_rest_contacts = 0;  ///< of true_contacts, the robot at rest at the first moment
  /// Against `none` (when it ran): paired per-scenario task-time ratios,
  /// the ratio of median task times, and the ratios of the totals of stops
  /// and of time in stop (a total of 0 for `none` gives 0 if this one is 0 too, else infinity).
  bool has_reference = false;
  Spread task_time_ratio;
  double task_time_median_ratio = 0;
  double protective_stops_ratio = 0;
  double stop_time_ratio = 0;
};

/// Summaries per predictor; `results[s][p]` is scenario s with predictor
/// `predictors[p]`.
std::vector<PredictorSummary> Summarize(const std::vector<Predictor>& predictors,
                                        const std::vector<std::vector<InteractionResult>>& results);

}  // namespace iplan::cell_sim

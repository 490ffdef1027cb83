// The robot cell in one process and in simulated time: one robot task
// (RunInteraction), or the tasks of a whole episode one after another
// (RunEpisode, the next chosen when the previous ends: TaskFeed), while a
// person moves nearby, closed through the same algorithm cores the services
// run (no DDS):
//
//   skeletons (sensor rate, observed = true + noise)
//     -> predictions (per skeleton: one source for the planner, one for the
//        collision-risk monitor; see PredictionSource)
//     -> trajopt::Replanner, one cycle per planning step
//     -> collision_risk::RiskMonitor, on every prediction and at its rate in
//        between; PROTECTIVE_STOP stops the robot at once (the monitor's own
//        permit), and it resumes only after every cause has been clear for
//        the resume delay (supervisor::SafetyMonitor, the supervisor's permit)
//     -> robot_sim::RobotSimulator at the control rate.
// The true (noise-free) skeleton decides contacts and the true separation
// (RobotSimulator::UpdateContacts, every control step) and the true bound
// (below). No sleeping and no wall clock: the run is a deterministic function
// of its inputs (planning times are measured, but change nothing).
//
// Timing model: a message is received the instant it is sent, and planning
// takes no simulated time (the replanner's frozen prefix is what the robot
// executes while the real service plans).
//
// Frames and units: world frame W (robot base, z up), m, rad, s. Scenario
// time t is s since the scenario start (the person's first frame); the cores
// see ns stamps SimTimeNs(t). Not thread-safe; RunInteraction may run on
// several threads with distinct inputs (the models are only read).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "services/trajopt/core/replanner.h"
#include "services/collision_risk/core/risk_monitor.h"
#include "services/robot_sim/core/robot_simulator.h"
#include "iplan/collision/human_model.h"
#include "iplan/collision/joint_mixture.h"
#include "iplan/planning/planner.h"

namespace iplan::cell_sim {

/// The ns stamp the cores see for scenario time `t` (s): an arbitrary epoch
/// plus t, so that no stamp is 0 (which the cores read as "none").
int64_t SimTimeNs(double t);

/// One person as the cell's sensor sees them: frames at the sensor rate,
/// frame i at t = i / rate_hz.
struct PersonStream {
  std::vector<std::string> joint_names;    ///< J, in the human body model's joint order
  double rate_hz = 30;                     ///< sensor rate, Hz
  std::vector<Eigen::Matrix3Xd> truth;     ///< per frame: true joint positions p_WJ, 3 x J (m)
  std::vector<Eigen::Matrix3Xd> observed;  ///< per frame: what the sensor reports (truth + noise)

  int num_frames() const { return static_cast<int>(truth.size()); }
  double stamp(int frame) const { return frame / rate_hz; }
  /// True pose at t (s): linear between frames, the first / last frame
  /// beyond the ends. `p_WJ` is resized to 3 x J.
  void TrueAt(double t, Eigen::Matrix3Xd* p_WJ) const;
  /// Empty when consistent, else why not (sizes, rate, non-finite values).
  std::string Validate() const;
};

/// The prediction made from frame `frame` (its t0_ns must be
/// SimTimeNs(stamp(frame))), or null for none. The pointer must stay valid
/// until the next call.
using PredictionSource = std::function<const collision::JointMixture*(int frame)>;

/// Joint covariances (J matrices, body joint order, m^2) for the true bound
/// at frame `frame`, or null for the isotropic LoopParams::true_bound_std.
using CovarianceSource = std::function<const std::vector<Eigen::Matrix3d>*(int frame)>;

/// What the cell is made of: the models are not owned and must outlive the run.
struct CellModels {
  const planning::Planner* planner = nullptr;            ///< the trajectory optimiser (replanning parameters)
  const collision::HumanBodyModel* body = nullptr;       ///< the human body model (planner and true body)
  const collision_risk::RiskMonitor* monitor = nullptr;  ///< a monitor that has seen nothing; copied per run
  trajopt::ReplannerParams replanner;
  robot_sim::SimulatorParams simulator;
};

struct LoopParams {
  double control_rate_hz = 100;     ///< Hz, robot simulation steps (robot_sim control_rate_hz)
  double joint_state_rate_hz = 50;  ///< Hz, robot states to the planner and the monitor (robot_sim publish_rate_hz)
  double monitor_rate_hz = 15;      ///< Hz, monitor evaluations between predictions (collision_risk rate_hz)
  double resume_delay = 0.5;        ///< s every stop cause stays clear before the robot resumes (supervisor resume_delay)
  double task_start = 1.0;          ///< s: the (first) task command, at the first planning cycle from then on
  double max_duration = 30;         ///< s after the (first) command: the run ends even without an outcome
  double true_bound_std = 0.05;     ///< m, per coordinate, when the CovarianceSource gives none
  /// Optional: told every planning cycle's status and every stop / resume
  /// with its reason (t in s of scenario time), to see why a run went as it
  /// did. Null: nothing is reported.
  std::function<void(double t, const std::string& event)> trace;
  /// Empty when valid, else the offending field and value.
  std::string Validate() const;
};

/// The robot's task: where it starts (at rest) and what it is commanded.
struct TaskSetup {
  Eigen::VectorXd start_q;  ///< rad, model joint order
  trajopt::TaskSpec task;   ///< time_limit is the replanner's (0: none)
};

/// rad/s: a contact counts as the robot's moving one when the robot's fastest
/// joint was faster than this at the contact's first moment, else as one
/// with the robot at rest (InteractionResult::robot_moving_contacts).
constexpr double kMovingContactSpeed = 0.01;

/// rad: a robot this near its goal or retreat (every joint) is arriving,
/// not waiting (InteractionResult::wait_time), however slowly it settles.
constexpr double kArrivingDistance = 0.05;

/// Figures of one run, from the task command to its outcome (or the end).
struct InteractionResult {
  bool finished = false;       ///< the replanner reported an outcome
  trajopt::TaskStatus status = trajopt::TaskStatus::kFailed;
  std::string reason;          ///< the outcome's reason, or why the run ended
  double task_time = 0;        ///< s, command to arrival (outcome duration); max_duration if unfinished
  double planner_delay = 0;    ///< s, the replanner's delay (waits, hold-offs, time in stop)
  uint32_t waits = 0;          ///< cycles whose plan inserted a wait
  int protective_stops = 0;    ///< times the robot was stopped (once if stopped at the command)
  int stops_separation = 0;    ///< of which the ISO/TS 15066 separation layer started
  int stops_bound = 0;         ///< of which the collision bound along the executing trajectory started
  double stop_time = 0;        ///< s the robot spent stopped
  /// s the robot stood still (no joint faster than kMovingContactSpeed)
  /// while not stopped and not arriving (farther than kArrivingDistance
  /// from the goal and the retreat), at the control rate: waiting for a
  /// safe plan or holding off for the person.
  double wait_time = 0;
  double command_time = 0;     ///< s, scenario time of the task's command
  int slow_downs = 0;          ///< times the monitor slowed the robot (speed reduction) from full speed
  double slow_time = 0;        ///< s the robot ran slowed down (its path time-scaled below 1)
  double min_separation = 1e6; ///< m, smallest true robot-human surface distance (control rate)
  /// Highest true bound: at every skeleton frame, the collision bound
  /// (METHOD 4) of the robot's actual configuration against the true body at
  /// that instant, the joints Gaussian with the CovarianceSource's
  /// covariances: what the bound would have been with a perfect prediction.
  double max_bound = 0;
  int true_contacts = 0;       ///< episodes of true contact (RobotSimulator::contacts)
  /// The contacts split by what the robot was doing at each one's first
  /// moment (the control step at which the true separation first went below
  /// the contact margin): moving (max |qd| > kMovingContactSpeed) or at rest
  /// (a person walking into a robot that stands still). They sum to
  /// true_contacts.
  int robot_moving_contacts = 0;
  int robot_at_rest_contacts = 0;
  std::vector<double> contact_speeds;  ///< rad/s per contact, in order: max |qd| at its first moment
  std::string first_stop_reason;  ///< the monitor's reason for the first stop ("" without)
  int planning_cycles = 0;
  std::vector<double> planning_times;  ///< s per cycle, wall time (not deterministic)
};

/// The tasks of a run, one after another (e.g. the task planner's episode).
struct TaskFeed {
  /// The next task, asked at a planning step when no task runs: the first
  /// from LoopParams::task_start on, then the first at least `pause` s after
  /// the previous outcome. `t`: scenario time (s); `frame`: the newest
  /// skeleton frame delivered (-1: none yet). nullopt: the run ends there.
  std::function<std::optional<trajopt::TaskSpec>(double t, int frame)> next;
  /// Told every outcome of a commanded task (`t`: scenario time of the
  /// planning step that reported it, s; `frame` as for next); returns
  /// whether another task follows (false, or no function: the run ends
  /// there).
  std::function<bool(double t, int frame, const trajopt::TaskOutcome& outcome)> done;
  double pause = 0;  ///< s from an outcome to the next task's command at the earliest (>= 0)
};

/// Figures of a run of tasks: each task's, and those of the whole run from
/// the first command to its end, between the tasks too.
struct EpisodeResult {
  /// One per commanded task, in order; when the run hit its limit the last
  /// one is unfinished (InteractionResult::finished false).
  std::vector<InteractionResult> tasks;
  bool ended_by_feed = false;  ///< the feed ended the run (else LoopParams::max_duration did)
  double duration = 0;         ///< s from the first command to the end of the run
  /// Contacts from the first command on, between tasks too (the robot then
  /// stands still, so those are robot_at_rest_contacts).
  int robot_moving_contacts = 0;
  int robot_at_rest_contacts = 0;
  double min_separation = 1e6;  ///< m, smallest true robot-human surface distance from the first command on
};

/// Runs the tasks `feed` gives, the robot starting at rest at `start_q`
/// (rad, model order), against one person; the cores (replanner, monitor,
/// robot) keep their state from one task to the next, as in the cell.
/// Predictions, covariances and throws as RunInteraction, and
/// std::invalid_argument without feed.next or with a negative pause.
/// Allocates.
EpisodeResult RunEpisode(const CellModels& models, const LoopParams& params, const Eigen::VectorXd& start_q,
                         const TaskFeed& feed, const PersonStream& person, const PredictionSource& planner_prediction,
                         const PredictionSource& monitor_prediction, const CovarianceSource& true_covariance);

/// Runs one task against one person. `planner_prediction` feeds the
/// replanner, `monitor_prediction` the monitor (either may return null: no
/// prediction; the monitor then runs degraded, on separation alone).
/// Throws std::invalid_argument on invalid params, an inconsistent stream,
/// a start outside the limits or a task the replanner refuses, and
/// std::runtime_error when a core refuses input the loop produced (a bug).
/// Allocates.
InteractionResult RunInteraction(const CellModels& models, const LoopParams& params, const TaskSetup& task,
                                 const PersonStream& person, const PredictionSource& planner_prediction,
                                 const PredictionSource& monitor_prediction, const CovarianceSource& true_covariance);

}  // namespace iplan::cell_sim

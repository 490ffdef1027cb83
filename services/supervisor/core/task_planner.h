// The task planner of METHOD 6: an MDP whose states are the progress of the
// whole task (a bitmask of finished robot sub-tasks over a precedence graph),
// whose actions are the robot sub-tasks available in a state, learned with
// Q-learning. The reward prefers tasks that do not conflict with what the
// person is predicted to do and penalises the delay a task caused:
//   r = h(s, a | p(c)) - w_d * delay,  h = 1 - sum_c p(c) conflict(a, c).
// Our extension of the reward: - w_t * (the task's time less its delay),
// so that the learned order also saves the robot's travel (w_t = 0:
// METHOD 6's reward).
// Our extension, the anticipating choice: the next task a maximises
//   Q(s, a) - min over continuations [w_c * E[conflict] + w_v * travel]
// of the sequence of a and up to anticipation_depth - 1 tasks after it:
// E[conflict] the expected seconds during which the person, forecast from
// the belief and the person's own task graph (core/human_graph.h), does an
// action a task conflicts with while it runs (durations learned from
// outcomes); travel the estimated seconds from where the robot stands (or
// the sequence's task before) to each task's goal (the largest joint move
// at travel_speed), so that the order does not send the arm back and
// forth. w_c = w_v = 0 is METHOD 6's choice.
// The Q-table is saved atomically and reloaded; a corrupt file is refused
// with a message and the previous good copy is used. The backup is only
// ever replaced by a file that passes the loader's checks, so it stays good
// however often a damaged main file is refused and saved over. No DDS
// types. Not thread-safe.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "services/supervisor/core/human_graph.h"
#include "iplan/core/name_value.h"

namespace iplan::supervisor {

/// A place of a task given as a tool pose in the cell (world) frame, so that
/// one cell description serves any arm: the planner's end effector
/// (end_effector_link and offset) at `position` with that link's z axis
/// along `z_axis`, free to turn about it. Solved for the robot at hand by
/// the planner's IK (ResolveTaskGoals, core/task_goals.h).
struct ToolPose {
  std::vector<double> position;             ///< m, [x, y, z]; empty: not given
  std::vector<double> z_axis = {0.0, 0.0, -1.0};  ///< direction of the tool's z axis (normalised)

  bool given() const { return !position.empty(); }
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(position, "m; [x, y, z] of the end effector, cell frame"));
    a->Visit(IPLAN_NVP(z_axis, "direction of the end effector's z axis, cell frame (default: down)"));
  }
  /// "" when valid (position empty or 3 finite values, z_axis 3 finite
  /// values, not zero), else the reason.
  std::string Validate() const;
};

struct RobotTask {
  std::string name;
  /// Joint goal (rad), robot joint order. Empty, or not of the robot's size,
  /// when the task is given by goal_pose (ResolveTaskGoals fills it).
  std::vector<double> goal;
  std::vector<std::string> after;         ///< tasks that must be finished first
  std::vector<std::string> conflicts_with; ///< human actions this task conflicts with
  /// Joint positions (rad) to withdraw to after the goal before the task
  /// counts as done (e.g. out of the person's space after a hand-over), so
  /// that the delay of leaving is charged to this task. Empty: none.
  std::vector<double> retreat = {};
  ToolPose goal_pose = {};                ///< the goal as a tool pose (any arm)
  ToolPose retreat_pose = {};             ///< the retreat as a tool pose (any arm)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP_REQUIRED(name, "unique task name"));
    a->Visit(IPLAN_NVP(goal, "rad; joint goal, robot joint order (goal, goal_pose or both)"));
    a->Visit(IPLAN_NVP(goal_pose, "the goal as a tool pose: position (m) and z_axis, cell frame (any arm)"));
    a->Visit(IPLAN_NVP(retreat, "rad; joint positions to withdraw to after the goal, [] = none"));
    a->Visit(IPLAN_NVP(retreat_pose, "the retreat as a tool pose (any arm)"));
    a->Visit(IPLAN_NVP(after, "tasks that must be finished first"));
    a->Visit(IPLAN_NVP(conflicts_with, "human actions this task conflicts with"));
  }
};

struct TaskGraph {
  std::vector<RobotTask> tasks;            ///< at most 63
  std::vector<std::string> human_actions;
  /// The task whose goal is where the robot rests between episodes (and
  /// starts from); empty: not said.
  std::string rest;
  /// The person's own task graph over human_actions (empty: not given).
  HumanGraph human_graph;

  /// The file's keys: human_actions, robot_tasks (the list of tasks), rest.
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(human_actions, "the human actions the belief is over"));
    a->Visit(core::MakeNameValue("robot_tasks", &tasks, "the robot's tasks, at most 63", true));
    a->Visit(IPLAN_NVP(rest, "the task whose goal the robot rests at between episodes and starts from"));
    a->Visit(IPLAN_NVP(human_graph, "the person's own task graph: durations and successors of the human actions"));
  }
  /// Empty when consistent (unique names, a goal or goal_pose each, known
  /// predecessors, actions and rest task, no cycles, a consistent
  /// human_graph), else the reason.
  std::string Validate() const;
};

/// Loads a task graph from YAML (core::LoadParamsFile: unknown keys, wrong
/// types, missing required keys and keys written twice in one mapping are
/// errors, and so is an empty file). Throws std::runtime_error naming the
/// file and key.
TaskGraph LoadTaskGraph(const std::string& path);

struct QLearningParams {
  double alpha = 0.2;         ///< learning rate
  double gamma = 0.6;         ///< discount
  double epsilon = 0.3;       ///< exploration in learning mode (before the first finished episode)
  /// Factor on epsilon per finished learning episode (our extension; 1 keeps
  /// it constant as in METHOD 6): exploration fades as the table learns.
  double epsilon_decay = 1.0;
  double epsilon_min = 0.0;   ///< floor of the decayed epsilon
  double delay_weight = 1.0;  ///< w_d, per second of delay
  /// w_t, per second of a task's time less its delay (our extension: the
  /// order's travel counts, not only its waits); 0: METHOD 6's reward.
  double duration_weight = 0.0;
  /// w_v, per second of estimated travel from where the robot stands (the
  /// task finished last: its retreat, else its goal; at an episode's start
  /// the rest task's goal) to a candidate's goal, subtracted in the choice
  /// (our extension, the planned part of the time a task takes); 0: off.
  double travel_weight = 0.0;
  /// rad/s; the estimate is max_j |q_goal_j - q_j| / travel_speed.
  double travel_speed = 1.0;
  /// w_c, per second of expected conflict of a task over its duration (our
  /// extension, the anticipating choice); 0: METHOD 6's choice (Q alone).
  double anticipation_weight = 0.0;
  /// Tasks in the sequence the choice looks at: the candidate and the
  /// continuation of up to depth - 1 tasks after it with the least cost,
  /// w_c * expected conflict + w_v * travel, each task's travel from the one
  /// before (1: the candidate alone).
  int anticipation_depth = 1;
  /// s a task is expected to take before it has been done once (then: the
  /// mean of its outcomes' durations less their delays).
  double task_duration_prior = 3.0;
  bool learning = true;       ///< false: deployment, greedy, no updates
  uint64_t seed = 1;
  /// The YAML keys (section supervisor); `learning` comes from the service's
  /// `mode`. Ranges: Validate().
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(alpha, "learning rate, in (0, 1]"));
    a->Visit(IPLAN_NVP(gamma, "discount, in [0, 1)"));
    a->Visit(IPLAN_NVP(epsilon, "exploration in learning mode, in [0, 1]"));
    a->Visit(IPLAN_NVP(epsilon_decay, "factor on epsilon per finished learning episode, in (0, 1]"));
    a->Visit(IPLAN_NVP(epsilon_min, "floor of the decayed epsilon, in [0, 1]"));
    a->Visit(IPLAN_NVP(delay_weight, "w_d, per second of delay, >= 0"));
    a->Visit(IPLAN_NVP(duration_weight, "w_t, per second of a task's time less its delay, >= 0; 0: METHOD 6's reward"));
    a->Visit(IPLAN_NVP(travel_weight,
                       "w_v, per second of estimated travel to a task's goal, subtracted in the choice, >= 0; 0: off"));
    a->Visit(IPLAN_NVP(travel_speed, "rad/s the travel estimate assumes for the largest joint move, > 0"));
    a->Visit(IPLAN_NVP(anticipation_weight,
                       "w_c, per second a task is expected to conflict with the person over its duration, >= 0; 0: off"));
    a->Visit(IPLAN_NVP(anticipation_depth,
                       "tasks the choice looks at (conflict and travel): the candidate and the best continuation, in [1, 8]"));
    a->Visit(IPLAN_NVP(task_duration_prior, "s a task is expected to take before it was done once, > 0"));
    a->Visit(IPLAN_NVP(seed, "seed of the exploration generator"));
  }
  std::string Validate() const;
};

using State = uint64_t;  ///< bit i set: robot task i finished

class TaskPlanner {
 public:
  /// Throws std::invalid_argument on an invalid graph or params.
  TaskPlanner(TaskGraph graph, QLearningParams params);

  const TaskGraph& graph() const { return graph_; }
  State state() const { return state_; }
  bool episode_done() const;
  /// Tasks available in the current state (predecessors done, not done yet).
  std::vector<int> Available() const;
  /// h(s, a | belief): 1 - sum_c p(c) conflict(a, c); belief over
  /// graph().human_actions (missing actions count as 0).
  double Harmony(int task, const std::map<std::string, double>& belief) const;
  /// Episodes finished in learning mode by this table (saved with it).
  uint64_t episodes_learned() const { return episodes_learned_; }
  /// Exploration of the next choice: max(epsilon_min, epsilon *
  /// epsilon_decay^episodes_learned()) while learning (never above epsilon),
  /// 0 in deployment.
  double Epsilon() const;
  /// Chooses the next task: epsilon-greedy in learning mode, greedy in
  /// deployment, on Q(s, a) - [w_c * expected conflict + w_v * travel] of a
  /// and of the continuation of up to anticipation_depth - 1 tasks after it
  /// that costs the least (the conflict term only with a belief; Q alone
  /// when both weights are 0); ties broken by the harmony with the belief,
  /// then by index. -1 when the episode is done. Allocates (the forecast).
  int Choose(const ActionOutlook& outlook);
  /// s of expected conflict of the sequence that starts with `task` (one
  /// available now) and continues with the continuation of up to
  /// anticipation_depth - 1 available tasks that has the least, each task
  /// taking TaskDuration from the end of the one before (the pause between
  /// tasks is not counted). With depth 1 this is ExpectedConflict.
  double AnticipatedConflict(int task, const ActionOutlook& outlook) const;
  /// s of `task`'s expected duration (TaskDuration) during which the person
  /// is expected to do an action the task conflicts with:
  /// sum over forecast steps of dt * sum_c p_k(c) conflict(task, c), the
  /// forecast from `outlook` and the graph's human_graph
  /// (ForecastActions, steps of kForecastStep). 0 with an empty belief.
  double ExpectedConflict(int task, const ActionOutlook& outlook) const;
  /// s per step of the forecast behind ExpectedConflict.
  static constexpr double kForecastStep = 0.1;
  /// s `task` is expected to take: the mean of the durations observed by
  /// ObserveDuration, else task_duration_prior.
  double TaskDuration(int task) const;
  /// Learns that `task` took `seconds` without its delay (an outcome's
  /// duration less its delay); ignored unless finite and > 0. Saved with the
  /// Q-table.
  void ObserveDuration(int task, double seconds);
  /// The largest delay (s) one task is charged: a finite but absurd delay
  /// from the network (1.7e308) would otherwise overflow the Q-values.
  static constexpr double kMaxDelay = 3600.0;
  /// Q-learning update after `task` ended with `delay` (s) and took
  /// `motion` s besides (its time less the delay), each clamped to
  /// [0, kMaxDelay]; advances the state when `succeeded` (counting the
  /// episode when that finishes it, in learning mode) and learns `motion` as
  /// the task's duration (ObserveDuration). Returns the reward.
  /// A non-finite delay or motion (NaN, inf) is refused: no update, NaN
  /// returned, counted in refused_outcomes(); the state still advances. So
  /// is an update that would make the Q-value non-finite (absurd weights).
  double Complete(int task, bool succeeded, double delay, const std::map<std::string, double>& belief,
                  double motion = 0.0);
  /// Outcomes Complete() did not learn from (see there), since construction.
  uint64_t refused_outcomes() const { return refused_outcomes_; }
  /// Starts a new episode (state 0).
  void ResetEpisode() {
    state_ = 0;
    last_ = -1;
  }
  /// The task finished last in this episode, -1 before the first.
  int last_task() const { return last_; }
  /// Estimated seconds from where the robot stands (see travel_weight) to
  /// `task`'s goal: the largest joint move over travel_speed; 0 when either
  /// place is not known as joint positions of one size.
  double Travel(int task) const;

  double Q(State s, int task) const;

  /// Writes the Q-table atomically to `path`. The previous `path` becomes
  /// `path.bak` only if it passes Load's checks (magic, checksum, this task
  /// graph, finite values); otherwise the backup is left as it is. Throws
  /// std::runtime_error on I/O errors, after counting the failure in
  /// save_failures() and keeping its message in last_save_error().
  void Save(const std::string& path);
  /// Save() calls that failed (threw), since construction.
  uint64_t save_failures() const { return save_failures_; }
  /// The message of the latest failed Save(); empty until one fails. A later
  /// successful save does not clear it: save_failures() tells whether
  /// failures go on.
  const std::string& last_save_error() const { return last_save_error_; }
  /// Loads `path`; if it is missing returns false (fresh table); if it is
  /// corrupt, has non-finite values or belongs to another task graph, tries
  /// `path.bak`. Throws std::runtime_error when neither is usable, with both
  /// reasons. `*note` says what happened (e.g. "qtable.bin is corrupt
  /// (...); refused it and loaded the previous good table qtable.bin.bak").
  /// First removes the temporaries of `path` and `path.bak` left by saves
  /// killed mid-write (core::RemoveStaleTempFiles), noted in `*note`.
  bool Load(const std::string& path, std::string* note);

 private:
  std::vector<double>& Row(State s);
  void Write(const std::string& path) const;
  bool LoadTable(const std::string& path, std::string* note);
  std::optional<std::string> TryLoad(const std::string& path);
  /// Checks the bytes of a table file named `path` (for messages); empty
  /// and fills the outputs when it is a good table of this graph, else the
  /// reason. Does not touch the planner.
  struct Table {
    std::map<State, std::vector<double>> q;
    uint64_t episodes = 0;
    std::vector<std::pair<uint64_t, double>> durations;  // empty: the file has none (format 1, 2)
  };
  std::optional<std::string> Parse(const std::string& data, const std::string& path, Table* table) const;
  // s of conflict of `task` over [from, from + TaskDuration(task)).
  double ExpectedConflict(int task, const ActionForecast& forecast, double from) const;
  // The least cost of up to `depth` tasks available in `state`, the first
  // starting at `from` (s) with the robot where `place` left it (-1: the
  // rest pose): conflict_weight * their expected conflict (none without a
  // forecast) + travel_weight * their travel, each from the one before.
  double BestContinuation(State state, const ActionForecast* forecast, double from, int place, int depth,
                          double conflict_weight, double travel_weight) const;
  // The cost of doing `task` (available in `state`) next, starting at
  // `from` (s) with the robot where `place` left it, and then the cheapest
  // continuation of up to depth - 1 tasks (BestContinuation's terms).
  double OrderCost(State state, const ActionForecast* forecast, double from, int place, int task, int depth,
                   double conflict_weight, double travel_weight) const;
  // Where the robot stands after `task`: its retreat, else its goal; for -1
  // the rest task's goal (nullptr without one).
  const std::vector<double>* PlaceAfter(int task) const;
  // s of travel from where `from_task` left the robot (-1: rest) to `task`'s
  // goal, as Travel.
  double TravelBetween(int from_task, int task) const;
  // The forecast long enough for the sequences from `state` (anticipation_depth tasks).
  ActionForecast SequenceForecast(State state, const ActionOutlook& outlook) const;
  std::vector<int> AvailableIn(State state) const;
  uint64_t GraphHash() const;

  TaskGraph graph_;
  QLearningParams params_;
  std::map<State, std::vector<double>> q_;
  State state_ = 0;
  int last_ = -1;  // the task finished last this episode, -1: none yet
  int rest_ = -1;  // the rest task, -1: none
  uint64_t episodes_learned_ = 0;
  uint64_t refused_outcomes_ = 0;
  uint64_t save_failures_ = 0;
  std::string last_save_error_;
  std::vector<uint64_t> prerequisites_;  // bitmask per task
  std::vector<std::pair<uint64_t, double>> durations_;  // per task: outcomes observed, their mean (s)
  std::mt19937_64 rng_;
};

}  // namespace iplan::supervisor

// The episode benchmark behind `iplan eval cell` (issue 26): whole episodes
// of the task graph, in simulated time, through the services' own cores
// (the supervisor's task planner choosing every task, intent, the
// trajectory optimiser, collision risk and the robot; RunEpisode), against
// the cell's synthetic person whose actions are drawn from the person's own
// task graph (TaskGraph::human_graph: what follows each action with which
// probability, and for how long), so that the next action is uncertain but
// predictable.
//
// An episode: the robot at rest at the graph's rest pose; the person part
// way through an action drawn from human_graph.start, then its successors;
// the task planner chooses a task at the first planning step from
// LoopParams::task_start, and the next one pause_between_tasks after each
// outcome, until every task succeeded or the episode limit. Everything an
// episode is made of (the person's actions and durations, their motion's
// variation, the sensor noise) is drawn from the benchmark seed and the
// episode index, and is the same for every predictor (paired).
//
// Each predictor has its own task planner, fresh at the first episode
// (supervisor.yaml's learning parameters, learning mode) and learning over
// the episodes in order, as the cell's supervisor does. What a predictor
// gives the planner and the monitor is as in `iplan eval interaction`
// (interaction_benchmark.h); what it gives the task planner:
//   none, constant-position, constant-velocity: nothing (Q alone; the
//       baselines forecast motion, not actions);
//   model:  the model's action belief at the newest skeleton and how long
//       its most likely action has lasted (supervisor::ActionTracker fed
//       every belief);
//   oracle: the true current action, when it ends and the true next action;
//   oracle-action: the true current action and how long it has lasted (a
//       perfect recogniser), nothing of when it ends or what follows; its
//       motion forecast is the current action's true motion continued (the
//       person's script with the action lasting for ever), so it measures
//       what a forecaster of each action's motion could give at best.
// CellBenchmarkSetup::oracle_error_std adds an error to both oracles'
// forecast means: how precise a forecast must be to gain what they gain.
//
// Units: m, rad, s; world frame W. Not thread-safe; allocates.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tools/cell_sim/core/interaction_benchmark.h"
#include "services/supervisor/core/task_planner.h"

namespace iplan::cell_sim {

/// Everything the episodes are made of.
struct CellBenchmarkSetup {
  /// The models, loop rates, intent model and estimator, baselines, the
  /// synthetic person and the sensor (recordings and tasks are not used).
  BenchmarkSetup base;
  /// The task graph, its goals in the robot's joints, with the person's
  /// human_graph (not empty).
  supervisor::TaskGraph graph;
  supervisor::QLearningParams learning;  ///< the task planners' (learning mode is forced)
  supervisor::ActionTrackerParams tracker;  ///< how model's belief dates its action (supervisor.yaml's)
  double pause_between_tasks = 0.5;      ///< s from an outcome to the next command
  double episode_limit = 120;            ///< s from the first command; an unfinished episode counts this long
  double task_time_limit = 20;           ///< s per task (the replanner fails it after)
  /// m per axis, >= 0: the oracles' (oracle, oracle-action) forecast means
  /// are off by e_j (k + 1) / D at step k of D, e_j ~ N(0, oracle_error_std^2
  /// I) drawn per frame and joint (seeded by the episode); 0: exact.
  double oracle_error_std = 0;
  /// Empty when usable, else why not (missing models, no human graph, a
  /// human action the synthetic person cannot do, goals not of the robot's
  /// size, no rest task, ...).
  std::string Validate() const;
};

/// One episode: what is drawn for it.
struct EpisodeSpec {
  int index = 0;
  uint64_t noise_seed = 0;   ///< of the sensor noise
  uint64_t person_seed = 0;  ///< of the synthetic person's variation
  /// The person's actions (episode time: 0 is the first frame); the first
  /// starts at or before 0, the last ends after the episode limit.
  std::vector<supervisor::HumanActionSpan> actions;
};

/// Draws `count` (>= 1) episodes from `seed` (episode k is the same whatever
/// the count). Throws std::invalid_argument on an unusable setup or count.
std::vector<EpisodeSpec> MakeCellEpisodes(const CellBenchmarkSetup& setup, int count, uint64_t seed);

/// One task of an episode as the task planner chose it.
struct ChosenTask {
  std::string task;
  std::string person_action;        ///< what the person truly did at the command
  double person_for = 0;            ///< s the person had been doing it at the command
  double expected_conflict = 0;     ///< s, the planner's ExpectedConflict of the chosen task (0 without a forecast)
  /// What the task planner was told: the belief's most likely action ("":
  /// nothing) and how long it had lasted (s).
  std::string believed_action;
  double believed_for = 0;
  InteractionResult result;
};

/// One predictor's run of one episode.
struct CellEpisodeResult {
  int episode = 0;
  Predictor predictor = Predictor::kNone;
  std::vector<ChosenTask> tasks;  ///< in command order
  bool complete = false;          ///< every task succeeded within the limit
  double episode_time = 0;        ///< s, first command to the last outcome; the limit when not complete
  double robot_idle = 0;          ///< s, sum over the tasks of stop_time + wait_time (stopped or standing while tasked)
  double stop_time = 0;           ///< s of robot_idle stopped
  double planner_delay = 0;       ///< s, sum of the replanner's task delays (waits, holding off, stops)
  int protective_stops = 0;
  int tasks_done = 0;             ///< tasks that succeeded
  int robot_moving_contacts = 0;  ///< from the first command to the end, between tasks too
  int robot_at_rest_contacts = 0;
  double min_separation = 1e6;    ///< m, true, from the first command on
  uint64_t episodes_learned = 0;  ///< the predictor's task planner's, after the episode
};

/// The task planners of `predictors`, one each, fresh (same seed each).
/// Throws std::invalid_argument as supervisor::TaskPlanner.
std::vector<std::unique_ptr<supervisor::TaskPlanner>> MakeCellPlanners(const CellBenchmarkSetup& setup,
                                                                       const std::vector<Predictor>& predictors);

/// The person of `spec` as the episode's runs see them: true and observed
/// skeletons at the sensor rate, for the episode limit and the forecast's
/// look-ahead past it. Throws std::invalid_argument on an unusable setup.
PersonStream EpisodePersonStream(const CellBenchmarkSetup& setup, const EpisodeSpec& spec);

/// What oracle-action knows while action `span` of `spec` goes on: the same
/// person with that action lasting for ever, so their motion up to its end
/// is the episode's; sampled to its end plus the forecast's look-ahead.
/// Throws std::invalid_argument on an unusable setup and std::out_of_range
/// when `span` is not an index of spec.actions.
PersonStream ContinuedActionStream(const CellBenchmarkSetup& setup, const EpisodeSpec& spec, std::size_t span);

/// Runs `spec` once per predictor, predictor p with (*planners)[p], which
/// learns from it and starts its next episode afterwards. Results in the
/// predictors' order. Throws as RunEpisode, and std::invalid_argument on an
/// unusable setup or a planner count that is not the predictors'.
std::vector<CellEpisodeResult> RunCellEpisode(const CellBenchmarkSetup& setup, const EpisodeSpec& spec,
                                              const std::vector<Predictor>& predictors,
                                              std::vector<std::unique_ptr<supervisor::TaskPlanner>>* planners);

/// One predictor's figures over the episodes.
struct CellSummary {
  Predictor predictor = Predictor::kNone;
  int episodes = 0;
  int complete = 0;
  Spread episode_time;  ///< s
  Spread robot_idle;    ///< s
  double robot_idle_total = 0;
  int protective_stops = 0;  ///< total
  int robot_moving_contacts = 0;
  int robot_at_rest_contacts = 0;
  int tasks_done = 0;  ///< total
  int tasks_total = 0; ///< episodes x tasks of the graph
  /// What the task planner was told at its choices (predictors that give it
  /// a belief: model, oracle, oracle-action): the choices, those whose most
  /// likely action was the person's true one, and for those |believed_for -
  /// person_for|.
  int choices_with_belief = 0;
  int belief_right = 0;
  Spread age_error;  ///< s; empty (0) without a right belief
  /// Against `none` (when it ran): ratio of medians, and the median of the
  /// paired per-episode ratios, of episode time and robot idle.
  bool has_reference = false;
  double episode_time_ratio = 0, robot_idle_ratio = 0;
  Spread episode_time_paired_ratio, robot_idle_paired_ratio;
};

/// Summaries per predictor; `results[e][p]` is episode e with predictor
/// `predictors[p]`; `tasks_per_episode` the graph's task count.
std::vector<CellSummary> SummarizeCell(const std::vector<Predictor>& predictors,
                                       const std::vector<std::vector<CellEpisodeResult>>& results,
                                       int tasks_per_episode);

/// The share of the oracle's gain over `none` that `other` recovers:
/// (none - other) / (none - oracle) of a figure; NaN when the oracle gains
/// nothing (none <= oracle).
double GainRecovered(double none, double other, double oracle);

}  // namespace iplan::cell_sim

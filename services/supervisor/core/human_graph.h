// The person's own task graph (our extension of METHOD 6, which models only
// the robot's tasks): for every human action, how long it lasts (uniform
// between a least and a most) and which action follows it with which
// probability, and what the person is doing when an episode begins. It is a
// semi-Markov chain over the task graph's human actions.
//
// Two users:
//  - the anticipating task choice (core/anticipation.h) forecasts the
//    person's actions over a robot task's duration from the action belief
//    and this graph (ForecastActions);
//  - the cell benchmark's stochastic person (services/cell_sim) draws the
//    actions it performs (DrawHumanActions), so the same graph describes the
//    person the planner expects and the one it meets.
//
// Declared in the task graph file under `human_graph` (config/tasks/
// table_top.yaml); absent, the graph is empty: the person is taken to keep
// doing what the belief says. No DDS types. Units: s. Thread-safe (const).
#pragma once

#include <array>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "iplan/core/name_value.h"

namespace iplan::supervisor {

/// One action of the person's graph.
struct HumanActionStep {
  std::array<double, 2> duration = {1.0, 1.0};  ///< s, [least, most]; uniform between them
  std::map<std::string, double> next;           ///< the action that follows: probability each, summing to 1

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(duration, "s; [least, most] the action lasts (uniform between), 0 < least <= most"));
    a->Visit(IPLAN_NVP(next, "action: probability that it follows this one; the probabilities sum to 1"));
  }
};

struct HumanGraph {
  /// action: probability that the person is doing it when an episode
  /// begins (part way through it); sums to 1.
  std::map<std::string, double> start;
  /// One entry per human action the graph covers, in the file's order
  /// (core::Named: a mapping of name: step).
  std::vector<std::pair<std::string, HumanActionStep>> actions;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(start, "action: probability the person is doing it when an episode begins; sums to 1"));
    a->Visit(IPLAN_NVP(actions, "action: {duration: [least, most] s, next: {action: probability}}"));
  }
  bool empty() const { return actions.empty(); }
  /// Index of `action` in `actions`, or -1.
  int Find(const std::string& action) const;
  /// "" when consistent with the task graph's `human_actions` (every name
  /// one of them, every action's successors and the start distribution
  /// probabilities in [0, 1] summing to 1 within 1e-6, durations finite with
  /// 0 < least <= most, every successor and start action having an entry),
  /// else the reason. An empty graph is valid.
  std::string Validate(const std::vector<std::string>& human_actions) const;
};

/// One action of a drawn sequence.
struct HumanActionSpan {
  std::string action;
  double start = 0;     ///< s (episode time); the first span starts at or before 0
  double duration = 0;  ///< s
  double end() const { return start + duration; }
};

/// Draws the person's actions of an episode from `graph` (valid, not
/// empty): the first action from `start`, its whole duration from its range
/// and how much of it is already over at time 0 uniformly (so it starts at
/// -U * duration), then successors and durations until the spans reach
/// `until` (s, > 0). `uniform01` gives independent numbers in [0, 1) (the
/// caller's seeded stream; the draws use it in a fixed order, so a seed
/// gives the same sequence everywhere). Throws std::invalid_argument on an
/// empty graph or `until` <= 0. Allocates.
std::vector<HumanActionSpan> DrawHumanActions(const HumanGraph& graph, double until,
                                              const std::function<double()>& uniform01);

/// What the task chooser knows of the person when it chooses.
struct ActionOutlook {
  /// Action: probability that it is the person's current action (the
  /// newest belief); empty: nothing is known (no forecast).
  std::map<std::string, double> belief;
  double elapsed = 0;  ///< s the current action has lasted (an estimate, e.g. ActionTracker)
  /// True when the action began before anything was seen of the person (the
  /// first belief already showed it): it has lasted at least `elapsed`, and
  /// the forecast takes its age as that of an action met part way through,
  /// from `elapsed` on (ActionTracker::StartSeen false).
  bool elapsed_at_least = false;
  /// Only an oracle knows these: the current action ends in `remaining` s
  /// (< 0: unknown) and `next` follows it ("": unknown, the graph's
  /// successors).
  double remaining = -1;
  std::string next;
};

/// The person's actions forecast over the next steps.
struct ActionForecast {
  double dt = 0;  ///< s per step
  /// The graph's actions in its order, then the belief's actions the graph
  /// does not know (taken to last for ever).
  std::vector<std::string> actions;
  /// [step k][action]: probability that the person does the action at t = k dt.
  std::vector<std::vector<double>> p;
};

/// The forecast of the person's actions for `steps` steps of `dt` s from
/// now: the belief, each action ending after its remaining duration given
/// `elapsed` (one already past its most ends within the first step; an
/// oracle's `remaining` instead ends it then), followed by its successors
/// (an oracle's `next` instead, for the first change), they by theirs.
/// Actions the graph does not know keep their probability; an empty graph
/// keeps the belief for the whole forecast. Throws std::invalid_argument
/// when dt <= 0 or steps < 0. Allocates.
ActionForecast ForecastActions(const HumanGraph& graph, const ActionOutlook& outlook, double dt, int steps);

/// How the action tracker reads the belief stream (section supervisor of
/// supervisor.yaml; our extension, docs/supervisor.md "How long the action
/// has lasted"). Times in s.
struct ActionTrackerParams {
  /// A new most likely action is taken as a change of action only once it
  /// has stayed the most likely this long; a shorter flip (a reach's hand
  /// passing its rest between two reaches) does not restart the age. The
  /// change is then dated when the flip began. 0: every flip is a change.
  double action_switch_confirm = 0.0;
  /// How long after an action starts the belief makes it the most likely:
  /// added to the age of an action whose start was seen. 0: none.
  double action_recognition_delay = 0.0;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(action_switch_confirm,
                       "s a new most likely action must stay so before the person's action counts as changed, in [0, 10]"));
    a->Visit(IPLAN_NVP(action_recognition_delay,
                       "s the belief recognises an action after it starts, added to its age, in [0, 10]"));
  }
  /// "" when valid, else the reason naming the key.
  std::string Validate() const;
};

/// How long the person has been doing what the belief says: fed every
/// belief with its stamp, it keeps the person's action (the most likely one,
/// changed only after ActionTrackerParams::action_switch_confirm) and when
/// it began. Not thread-safe.
class ActionTracker {
 public:
  /// Throws std::invalid_argument when params.Validate() fails.
  explicit ActionTracker(const ActionTrackerParams& params = {});
  /// A belief (action: probability) at `stamp` (s, non-decreasing). An
  /// empty belief forgets the action (the next one starts unseen again).
  void Update(double stamp, const std::map<std::string, double>& belief);
  /// The person's action as tracked ("" before any belief).
  const std::string& action() const { return action_; }
  /// s the action has lasted at `now` (s): since it became the most likely
  /// one, plus action_recognition_delay when its start was seen; 0 before
  /// any belief, never negative.
  double Elapsed(double now) const;
  /// False while the action is the one the first belief showed: it began
  /// before anything was seen, and Elapsed is a lower bound.
  bool StartSeen() const { return start_seen_; }
  /// The outlook the task choice takes: `belief` (the newest), Elapsed(now)
  /// and whether that is a lower bound.
  ActionOutlook Outlook(const std::map<std::string, double>& belief, double now) const;

 private:
  ActionTrackerParams params_;
  std::string action_;
  double since_ = 0;
  bool start_seen_ = false;
  std::string candidate_;  // a new most likely action, not yet confirmed
  double candidate_since_ = 0;
};

}  // namespace iplan::supervisor

#include "tools/cell_sim/core/cell_benchmark.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "tools/cell_sim/core/person_motion.h"
#include "tools/cell_sim/core/prediction_sources.h"
#include "tools/cell_sim/core/scenario_draws.h"

namespace iplan::cell_sim {

using namespace internal;

namespace {

// s of person an episode needs: the limit, the first command and the
// oracle's look-ahead past the end.
double StreamDuration(const CellBenchmarkSetup& setup) {
  const auto& config = setup.base.intent_model->config;
  return setup.base.loop.task_start + setup.episode_limit + config.horizon / config.rate + 1.0;
}

// The person of an episode: the cell's synthetic person doing the drawn
// actions, already part way through the first at the episode's start,
// sampled for `duration` s.
PersonStream EpisodePerson(const CellBenchmarkSetup& setup, const EpisodeSpec& spec, double duration) {
  perception::SyntheticPersonParams person = setup.base.person;
  person.script.clear();
  for (const auto& a : spec.actions) person.script.push_back({a.action, a.duration});
  person.seed = spec.person_seed;
  SyntheticPlacement place;
  place.script_start = spec.actions.front().start;
  return SyntheticPersonStream(person, place, setup.base.models.body->params().joints, setup.base.sensor_rate_hz,
                               duration, setup.base.sensor_noise_std, spec.noise_seed);
}

// The span of `actions` going on at t (the last one after them all).
std::size_t SpanAt(const std::vector<supervisor::HumanActionSpan>& actions, double t) {
  for (std::size_t i = 0; i < actions.size(); ++i) {
    if (t < actions[i].end()) return i;
  }
  return actions.size() - 1;
}

// ContinuedActionStream without the checks (span < spec.actions.size()).
PersonStream ContinuedPerson(const CellBenchmarkSetup& setup, const EpisodeSpec& spec, std::size_t span) {
  EpisodeSpec continued = spec;
  continued.actions.resize(span + 1);
  const auto& config = setup.base.intent_model->config;
  const double duration =
      std::min(StreamDuration(setup), spec.actions[span].end() + config.horizon / config.rate + 1.0);
  continued.actions[span].duration += StreamDuration(setup);  // beyond any time asked for
  return EpisodePerson(setup, continued, duration);
}

// oracle-action's future at a frame: ContinuedPerson of the span going on
// then, made when first asked for.
class ContinuedActions {
 public:
  ContinuedActions(const CellBenchmarkSetup& setup, const EpisodeSpec& spec, const PersonStream& person)
      : setup_(setup), spec_(spec), person_(person), streams_(spec.actions.size()) {}

  const PersonStream& At(int frame) {
    const std::size_t i = SpanAt(spec_.actions, person_.stamp(frame));
    if (!streams_[i]) streams_[i] = ContinuedPerson(setup_, spec_, i);
    return *streams_[i];
  }

 private:
  const CellBenchmarkSetup& setup_;
  const EpisodeSpec& spec_;
  const PersonStream& person_;
  std::vector<std::optional<PersonStream>> streams_;
};

// What a predictor tells the task planner about the person (see the top of
// cell_benchmark.h): at a time t, with the newest skeleton frame.
class PersonOutlook {
 public:
  PersonOutlook(Predictor p, const EpisodeSpec& spec, const PersonStream& person, ModelTrack* track,
                const supervisor::ActionTrackerParams& tracker)
      : predictor_(p), spec_(spec), person_(person), track_(track), tracker_(tracker) {}

  supervisor::ActionOutlook At(double t, int frame) {
    supervisor::ActionOutlook o;
    if (predictor_ == Predictor::kOracle || predictor_ == Predictor::kOracleAction) {
      const std::size_t i = SpanAt(spec_.actions, t);
      const supervisor::HumanActionSpan& span = spec_.actions[i];
      o.belief = {{span.action, 1.0}};
      o.elapsed = t - span.start;
      if (predictor_ == Predictor::kOracle) {
        o.remaining = std::max(0.0, span.end() - t);
        if (i + 1 < spec_.actions.size()) o.next = spec_.actions[i + 1].action;
      }
    } else if (predictor_ == Predictor::kModel) {
      // Every belief up to the newest frame, as the supervisor receives them.
      for (; fed_ < frame; ++fed_) {
        const collision::JointMixture* m = track_->At(fed_ + 1);
        if (!m) continue;
        belief_.clear();
        for (std::size_t a = 0; a < m->actions.size(); ++a) belief_[m->actions[a]] = m->probabilities[a];
        tracker_.Update(person_.stamp(fed_ + 1), belief_);
      }
      if (frame >= 0) o = tracker_.Outlook(belief_, person_.stamp(frame));
    }
    return o;
  }

 private:
  Predictor predictor_;
  const EpisodeSpec& spec_;
  const PersonStream& person_;
  ModelTrack* track_;
  int fed_ = -1;  // newest frame fed to the tracker
  std::map<std::string, double> belief_;
  supervisor::ActionTracker tracker_;
};

// One predictor's episode: the task planner choosing and learning through
// the loop's task feed.
CellEpisodeResult RunOne(const CellBenchmarkSetup& setup, const EpisodeSpec& spec, Predictor p,
                         const PersonStream& person, ModelTrack* track, const TrueCovariances& covariances,
                         const OracleOptions& oracle, supervisor::TaskPlanner* planner) {
  const supervisor::TaskGraph& graph = planner->graph();
  const PredictorSources sources(setup.base, person, track, p, oracle);
  PersonOutlook outlook(p, spec, person, track, setup.tracker);
  CellEpisodeResult out;
  out.episode = spec.index;
  out.predictor = p;
  int current = -1;
  uint32_t id = 0;
  TaskFeed feed;
  feed.pause = setup.pause_between_tasks;
  feed.next = [&](double t, int frame) -> std::optional<trajopt::TaskSpec> {
    const supervisor::ActionOutlook o = outlook.At(t, frame);
    current = planner->Choose(o);
    if (current < 0) return std::nullopt;
    const supervisor::RobotTask& task = graph.tasks[static_cast<std::size_t>(current)];
    ChosenTask chosen;
    chosen.task = task.name;
    const supervisor::HumanActionSpan& truth = spec.actions[SpanAt(spec.actions, t)];
    chosen.person_action = truth.action;
    chosen.person_for = t - truth.start;
    chosen.expected_conflict = planner->ExpectedConflict(current, o);
    if (!o.belief.empty()) {
      chosen.believed_action = std::max_element(o.belief.begin(), o.belief.end(), [](const auto& a, const auto& b) {
                                 return a.second < b.second;
                               })->first;
      chosen.believed_for = o.elapsed;
    }
    out.tasks.push_back(std::move(chosen));
    trajopt::TaskSpec s;
    s.id = ++id;
    s.name = task.name;
    s.goal = planning::Goal::Joint(Eigen::Map<const Eigen::VectorXd>(task.goal.data(), static_cast<Eigen::Index>(task.goal.size())));
    s.retreat = Eigen::Map<const Eigen::VectorXd>(task.retreat.data(), static_cast<Eigen::Index>(task.retreat.size()));
    s.time_limit = setup.task_time_limit;
    return s;
  };
  feed.done = [&](double t, int frame, const trajopt::TaskOutcome& o) {
    const bool ok = o.status == trajopt::TaskStatus::kSucceeded;
    planner->Complete(current, ok, o.delay, outlook.At(t, frame).belief, o.duration - o.delay);
    return !planner->episode_done();
  };
  const supervisor::RobotTask& rest = graph.tasks[static_cast<std::size_t>(
      std::find_if(graph.tasks.begin(), graph.tasks.end(), [&](const auto& t) { return t.name == graph.rest; }) -
      graph.tasks.begin())];
  const Eigen::VectorXd start_q = Eigen::Map<const Eigen::VectorXd>(rest.goal.data(), static_cast<Eigen::Index>(rest.goal.size()));
  LoopParams loop = setup.base.loop;
  loop.max_duration = setup.episode_limit;
  const EpisodeResult run = RunEpisode(setup.base.models, loop, start_q, feed, person, sources.planner(),
                                       sources.monitor(), covariances.source());
  out.complete = planner->episode_done() && run.ended_by_feed;
  planner->ResetEpisode();
  out.episode_time = out.complete ? run.duration : setup.episode_limit;
  for (std::size_t i = 0; i < run.tasks.size() && i < out.tasks.size(); ++i) {
    const InteractionResult& r = run.tasks[i];
    out.tasks[i].result = r;
    out.robot_idle += r.stop_time + r.wait_time;
    out.stop_time += r.stop_time;
    out.planner_delay += r.planner_delay;
    out.protective_stops += r.protective_stops;
    if (r.finished && r.status == trajopt::TaskStatus::kSucceeded) ++out.tasks_done;
  }
  out.robot_moving_contacts = run.robot_moving_contacts;
  out.robot_at_rest_contacts = run.robot_at_rest_contacts;
  out.min_separation = run.min_separation;
  out.episodes_learned = planner->episodes_learned();
  return out;
}

}  // namespace

std::string CellBenchmarkSetup::Validate() const {
  const CellModels& m = base.models;
  if (!m.planner || !m.body || !m.monitor) return "the planner, body or monitor model is missing";
  if (!base.intent_model) return "no intent model";
  if (const std::string why = base.loop.Validate(); !why.empty()) return why;
  if (const std::string why = base.estimator.Validate(); !why.empty()) return "intent estimator: " + why;
  if (const std::string why = base.constant_position.Validate(); !why.empty()) return "constant position: " + why;
  if (const std::string why = base.constant_velocity.Validate(); !why.empty()) return "constant velocity: " + why;
  if (const std::string why = base.person.Validate(); !why.empty()) return "synthetic person: " + why;
  if (!(base.sensor_rate_hz > 0) || !(base.sensor_noise_std >= 0)) return "sensor rate must be > 0 and noise >= 0";
  if (const std::string why = graph.Validate(); !why.empty()) return "task graph: " + why;
  if (graph.human_graph.empty()) return "the task graph has no human_graph (the person's actions cannot be drawn)";
  for (const auto& [name, step] : graph.human_graph.actions) {
    if (std::none_of(base.person.actions.begin(), base.person.actions.end(),
                     [&](const perception::ActionMotion& a) { return a.name == name; })) {
      return "the synthetic person has no action '" + name + "' of the human graph";
    }
  }
  const int nq = m.planner->robot().nq;
  for (const auto& t : graph.tasks) {
    if (static_cast<int>(t.goal.size()) != nq || (!t.retreat.empty() && static_cast<int>(t.retreat.size()) != nq)) {
      return "task '" + t.name + "' does not have one position per robot joint";
    }
  }
  if (graph.rest.empty()) return "the task graph names no rest task (where the robot starts)";
  if (const std::string why = learning.Validate(); !why.empty()) return "learning: " + why;
  if (!(pause_between_tasks >= 0)) return "pause_between_tasks must be >= 0";
  if (!(episode_limit > 0) || !(task_time_limit > 0)) return "the episode and task limits must be > 0";
  if (!(oracle_error_std >= 0) || !std::isfinite(oracle_error_std)) return "oracle_error_std must be finite and >= 0";
  return "";
}

std::vector<EpisodeSpec> MakeCellEpisodes(const CellBenchmarkSetup& setup, int count, uint64_t seed) {
  if (const std::string why = setup.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (count < 1) throw std::invalid_argument("the number of episodes must be >= 1, got " + std::to_string(count));
  std::vector<EpisodeSpec> out;
  for (int i = 0; i < count; ++i) {
    Draws d(Mix(seed) ^ Mix(0xce11e000ULL + static_cast<uint64_t>(i)));
    EpisodeSpec e;
    e.index = i;
    e.noise_seed = d.Next();
    e.person_seed = d.Next();
    e.actions = supervisor::DrawHumanActions(setup.graph.human_graph, StreamDuration(setup),
                                             [&d] { return d.Uniform(0.0, 1.0); });
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<std::unique_ptr<supervisor::TaskPlanner>> MakeCellPlanners(const CellBenchmarkSetup& setup,
                                                                       const std::vector<Predictor>& predictors) {
  supervisor::QLearningParams q = setup.learning;
  q.learning = true;
  std::vector<std::unique_ptr<supervisor::TaskPlanner>> out;
  for (std::size_t i = 0; i < predictors.size(); ++i) out.push_back(std::make_unique<supervisor::TaskPlanner>(setup.graph, q));
  return out;
}

PersonStream EpisodePersonStream(const CellBenchmarkSetup& setup, const EpisodeSpec& spec) {
  if (const std::string why = setup.Validate(); !why.empty()) throw std::invalid_argument(why);
  return EpisodePerson(setup, spec, StreamDuration(setup));
}

PersonStream ContinuedActionStream(const CellBenchmarkSetup& setup, const EpisodeSpec& spec, std::size_t span) {
  if (const std::string why = setup.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (span >= spec.actions.size()) {
    throw std::out_of_range("ContinuedActionStream: span " + std::to_string(span) + " of " +
                            std::to_string(spec.actions.size()) + " actions");
  }
  return ContinuedPerson(setup, spec, span);
}

std::vector<CellEpisodeResult> RunCellEpisode(const CellBenchmarkSetup& setup, const EpisodeSpec& spec,
                                              const std::vector<Predictor>& predictors,
                                              std::vector<std::unique_ptr<supervisor::TaskPlanner>>* planners) {
  if (const std::string why = setup.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (planners->size() != predictors.size()) throw std::invalid_argument("RunCellEpisode: one task planner per predictor");
  const PersonStream person = EpisodePerson(setup, spec, StreamDuration(setup));
  ModelTrack track(setup.base, person);
  const TrueCovariances covariances(setup.base, &track);
  ContinuedActions continued(setup, spec, person);
  OracleOptions oracle;
  oracle.action_continued = [&continued](int frame) -> const PersonStream& { return continued.At(frame); };
  oracle.error_std = setup.oracle_error_std;
  oracle.error_seed = Mix(spec.noise_seed ^ 0x0ac1e000ULL);
  std::vector<CellEpisodeResult> out;
  for (std::size_t p = 0; p < predictors.size(); ++p) {
    out.push_back(RunOne(setup, spec, predictors[p], person, &track, covariances, oracle, (*planners)[p].get()));
  }
  return out;
}

double GainRecovered(double none, double other, double oracle) {
  if (!(none > oracle)) return std::numeric_limits<double>::quiet_NaN();
  return (none - other) / (none - oracle);
}

std::vector<CellSummary> SummarizeCell(const std::vector<Predictor>& predictors,
                                       const std::vector<std::vector<CellEpisodeResult>>& results,
                                       int tasks_per_episode) {
  const auto none_it = std::find(predictors.begin(), predictors.end(), Predictor::kNone);
  const std::ptrdiff_t none = none_it == predictors.end() ? -1 : none_it - predictors.begin();
  auto ratio = [](double a, double b) {
    return b > 0 ? a / b : (a > 0 ? std::numeric_limits<double>::infinity() : 1.0);
  };
  std::vector<CellSummary> out;
  for (std::size_t p = 0; p < predictors.size(); ++p) {
    CellSummary s;
    s.predictor = predictors[p];
    std::vector<double> time, idle, none_time, none_idle, time_ratio, idle_ratio, age_error;
    for (const auto& episode : results) {
      const CellEpisodeResult& r = episode.at(p);
      ++s.episodes;
      if (r.complete) ++s.complete;
      time.push_back(r.episode_time);
      idle.push_back(r.robot_idle);
      s.robot_idle_total += r.robot_idle;
      s.protective_stops += r.protective_stops;
      s.robot_moving_contacts += r.robot_moving_contacts;
      s.robot_at_rest_contacts += r.robot_at_rest_contacts;
      s.tasks_done += r.tasks_done;
      s.tasks_total += tasks_per_episode;
      for (const ChosenTask& t : r.tasks) {
        if (t.believed_action.empty()) continue;
        ++s.choices_with_belief;
        if (t.believed_action != t.person_action) continue;
        ++s.belief_right;
        age_error.push_back(std::abs(t.believed_for - t.person_for));
      }
      if (none >= 0) {
        const CellEpisodeResult& n = episode.at(static_cast<std::size_t>(none));
        none_time.push_back(n.episode_time);
        none_idle.push_back(n.robot_idle);
        time_ratio.push_back(ratio(r.episode_time, n.episode_time));
        idle_ratio.push_back(ratio(r.robot_idle, n.robot_idle));
      }
    }
    s.episode_time = SpreadOf(time);
    s.robot_idle = SpreadOf(idle);
    if (!age_error.empty()) s.age_error = SpreadOf(age_error);
    if (none >= 0) {
      s.has_reference = true;
      s.episode_time_ratio = ratio(s.episode_time.median, SpreadOf(none_time).median);
      s.robot_idle_ratio = ratio(s.robot_idle.median, SpreadOf(none_idle).median);
      s.episode_time_paired_ratio = SpreadOf(time_ratio);
      s.robot_idle_paired_ratio = SpreadOf(idle_ratio);
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace iplan::cell_sim

#include "tools/cell_sim/core/interaction_benchmark.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>

#include "tools/cell_sim/core/person_motion.h"
#include "tools/cell_sim/core/prediction_sources.h"
#include "tools/cell_sim/core/scenario_draws.h"
#include "iplan/collision/robot_model.h"
#include "iplan/core/stats.h"

namespace iplan::cell_sim {
namespace internal {

std::vector<NamedPose> GraphPoses(const std::vector<GraphTask>& tasks) {
  std::vector<NamedPose> poses;
  for (const auto& t : tasks) {
    poses.push_back({t.name, t.goal});
    if (t.retreat.size() > 0) poses.push_back({t.name + ".retreat", t.retreat});
  }
  return poses;
}

// A sequence every joint of which is detected somewhere, the shoulders in
// the same frame at least once (RecordedPersonStream can use it).
bool Usable(const intent::SkeletonDataset& data, const intent::SkeletonSequence& s) {
  const Eigen::Index J = static_cast<Eigen::Index>(data.joint_names.size());
  std::vector<bool> seen(static_cast<std::size_t>(J), false);
  for (Eigen::Index i = 0; i < s.positions.rows(); ++i) {
    for (Eigen::Index j = 0; j < J; ++j) {
      if (intent::JointDetected(s.positions.row(i).segment(3 * j, 3))) seen[static_cast<std::size_t>(j)] = true;
    }
  }
  return std::find(seen.begin(), seen.end(), false) == seen.end();
}

// Where the end effector is at q (W).
Eigen::Isometry3d EndEffectorPose(const planning::Planner& planner, const Eigen::VectorXd& q) {
  const collision::RobotModel& robot = planner.robot();
  collision::RobotData data(robot);
  collision::CalcForwardKinematics(robot, q, &data);
  const int link = robot.FindLink(planner.params().end_effector_link);
  const auto& o = planner.params().end_effector_offset;
  Eigen::Isometry3d X = data.X_WL[static_cast<std::size_t>(link)];
  X.translation() = X * Eigen::Vector3d(o[0], o[1], o[2]);
  return X;
}


// A recorded person seated across the table: shoulders from above its far
// edge (x = 1.05 m) to 0.2 m behind it, at the synthetic person's shoulder
// height; the recorded hands work 0.1-0.5 m in front of them.
void DrawRecordedPerson(const std::vector<std::string>& subjects,
                        const std::map<std::string, std::vector<const intent::SkeletonSequence*>>& by_subject,
                        int recorded, Draws* d, ScenarioSpec* s) {
  s->source = "recorded";
  s->subject = subjects[static_cast<std::size_t>(recorded) % subjects.size()];
  const auto& list = by_subject.at(s->subject);
  const intent::SkeletonSequence& seq = *list[static_cast<std::size_t>(d->Index(list.size()))];
  s->sequence = seq.id;
  s->placement_W = {d->Uniform(1.05, 1.25), d->Uniform(-0.3, 0.3), 0.5};
  s->yaw = d->Uniform(-0.3, 0.3);
  const double length = seq.time.size() > 0 ? seq.time(seq.time.size() - 1) - seq.time(0) : 0.0;
  s->clip_start = d->Uniform(0.0, std::max(0.0, length - 12.0));
  s->delay = d->Uniform(0.0, 2.0);
}

// The synthetic person near its configured place, from well into its
// script (assembling) to not yet started (idle).
void DrawSyntheticPerson(const perception::SyntheticPersonParams& person, const std::string& script, Draws* d,
                         ScenarioSpec* s) {
  s->source = "synthetic";
  s->subject = "synthetic";
  s->sequence = script.empty() ? person.actions.front().name : script;
  s->placement_W = person.torso_W + Eigen::Vector3d(d->Uniform(-0.15, 0.05), d->Uniform(-0.2, 0.2), 0.0);
  s->yaw = d->Uniform(-0.2, 0.2);
  s->delay = d->Uniform(-9.0, 2.0);
}

// A task of the graph, started from a pose far from its goal and retreat.
void DrawGraphTask(const std::vector<GraphTask>& tasks, const std::vector<NamedPose>& poses, Draws* d,
                   ScenarioSpec* s) {
  const GraphTask& t = tasks[static_cast<std::size_t>(d->Index(tasks.size()))];
  s->task = t.name;
  s->goal_q = t.goal;
  s->retreat_q = t.retreat;
  std::vector<const NamedPose*> starts;
  for (const auto& p : poses) {
    const bool far_from = (p.q - t.goal).cwiseAbs().maxCoeff() > 0.3 &&
                          (t.retreat.size() == 0 || (p.q - t.retreat).cwiseAbs().maxCoeff() > 0.3);
    if (far_from) starts.push_back(&p);
  }
  if (starts.empty()) starts.push_back(&poses.front());
  const NamedPose& start = *starts[static_cast<std::size_t>(d->Index(starts.size()))];
  s->start = start.name;
  s->start_q = start.q;
}

// A reach: a flange pose over the table in front of the robot, towards the
// person, reachable and clear of the scene, keeping the home orientation
// turned about the vertical.
void DrawReach(const planning::Planner& planner, const std::vector<NamedPose>& poses, const Eigen::VectorXd& home,
               const Eigen::Matrix3d& R_home, Draws* d, ScenarioSpec* s) {
  s->task = "reach";
  const NamedPose& start = poses[static_cast<std::size_t>(d->Index(poses.size()))];
  s->start = start.name;
  s->start_q = start.q;
  for (int attempt = 0; attempt < 100; ++attempt) {
    const Eigen::Vector3d p(d->Uniform(0.40, 0.70), d->Uniform(-0.35, 0.35), d->Uniform(0.28, 0.40));
    const Eigen::Matrix3d R = Eigen::AngleAxisd(d->Uniform(-0.5, 0.5), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_home;
    const planning::IkResult ik = planner.SolveIk(p, Eigen::Quaterniond(R), home, d->Next());
    if (!ik.success) continue;
    if (planner.CalcClearance(ik.q) < planner.params().min_clearance + 0.02) continue;
    if ((ik.q - s->start_q).cwiseAbs().maxCoeff() < 0.3) continue;
    s->goal_q = ik.q;
    s->reach_p_WE = p;
    return;
  }
  throw std::runtime_error("scenario " + std::to_string(s->index) + ": no reachable table-top pose found");
}

// The person of a scenario as the sensor sees it and as it truly moves.
PersonStream MakePersonStream(const BenchmarkSetup& setup, const ScenarioSpec& spec, double duration) {
  const std::vector<std::string>& body_joints = setup.models.body->params().joints;
  if (spec.source == "recorded") {
    RecordedPlacement place;
    place.shoulder_centre_W = spec.placement_W;
    place.yaw = spec.yaw;
    place.clip_start = spec.clip_start;
    place.delay = spec.delay;
    return RecordedPersonStream(*setup.recordings, setup.recordings_file, spec.sequence, setup.joint_map, place,
                                body_joints, setup.sensor_rate_hz, duration, setup.sensor_noise_std, spec.seed);
  }
  if (spec.source == "synthetic") {
    SyntheticPlacement place;
    place.torso_offset_W = spec.placement_W - setup.person.torso_W;
    place.yaw = spec.yaw;
    place.script_start = spec.delay;
    place.sweep = spec.sweep;
    if (spec.person_actions.empty() && spec.person_script.empty()) {
      return SyntheticPersonStream(setup.person, place, body_joints, setup.sensor_rate_hz, duration,
                                   setup.sensor_noise_std, spec.seed);
    }
    perception::SyntheticPersonParams person = setup.person;
    for (const auto& a : spec.person_actions) {
      const auto it = std::find_if(person.actions.begin(), person.actions.end(),
                                   [&](const perception::ActionMotion& b) { return b.name == a.name; });
      if (it != person.actions.end()) {
        *it = a;
      } else {
        person.actions.push_back(a);
      }
    }
    if (!spec.person_script.empty()) person.script = spec.person_script;
    if (const std::string why = person.Validate(); !why.empty()) {
      throw std::invalid_argument("scenario " + std::to_string(spec.index) + ": synthetic person: " + why);
    }
    return SyntheticPersonStream(person, place, body_joints, setup.sensor_rate_hz, duration, setup.sensor_noise_std,
                                 spec.seed);
  }
  throw std::invalid_argument("scenario " + std::to_string(spec.index) + ": unknown source '" + spec.source + "'");
}

}  // namespace internal

using namespace internal;

collision::JointMixture Stamped(collision::JointMixture m, const std::vector<std::string>& joints, int64_t t0_ns) {
  m.t0_ns = t0_ns;
  m.joint_names = joints;
  return m;
}

const char* ToString(Predictor p) {
  switch (p) {
    case Predictor::kNone: return "none";
    case Predictor::kConstantPosition: return "constant-position";
    case Predictor::kConstantVelocity: return "constant-velocity";
    case Predictor::kModel: return "model";
    case Predictor::kOracle: return "oracle";
    case Predictor::kOracleAction: return "oracle-action";
  }
  return "unknown";
}

std::vector<std::string> PredictorNames() {
  std::vector<std::string> names;
  for (Predictor p : {Predictor::kNone, Predictor::kConstantPosition, Predictor::kConstantVelocity, Predictor::kModel,
                      Predictor::kOracle, Predictor::kOracleAction}) {
    names.push_back(ToString(p));
  }
  return names;
}

std::optional<Predictor> ParsePredictor(const std::string& name) {
  for (Predictor p : {Predictor::kNone, Predictor::kConstantPosition, Predictor::kConstantVelocity, Predictor::kModel,
                      Predictor::kOracle, Predictor::kOracleAction}) {
    if (name == ToString(p)) return p;
  }
  return std::nullopt;
}

const char* ToString(Suite s) {
  switch (s) {
    case Suite::kDefault: return "default";
    case Suite::kSharedSpace: return "shared-space";
  }
  return "unknown";
}

std::optional<Suite> ParseSuite(const std::string& name) {
  for (Suite s : {Suite::kDefault, Suite::kSharedSpace}) {
    if (name == ToString(s)) return s;
  }
  return std::nullopt;
}

std::vector<std::string> SuiteNames() { return {ToString(Suite::kDefault), ToString(Suite::kSharedSpace)}; }

std::string BenchmarkSetup::Validate() const {
  if (!models.planner || !models.body || !models.monitor) return "the planner, body or monitor model is missing";
  if (!intent_model) return "no intent model";
  if (!recordings || recordings->sequences.empty()) return "no recorded motion";
  if (const std::string why = loop.Validate(); !why.empty()) return why;
  if (const std::string why = estimator.Validate(); !why.empty()) return "intent estimator: " + why;
  if (const std::string why = constant_position.Validate(); !why.empty()) return "constant position: " + why;
  if (const std::string why = constant_velocity.Validate(); !why.empty()) return "constant velocity: " + why;
  if (const std::string why = person.Validate(); !why.empty()) return "synthetic person: " + why;
  if (GraphPoses(tasks).size() < 2) return "the task graph needs at least two poses";
  if (!(sensor_rate_hz > 0) || !(sensor_noise_std >= 0)) return "sensor rate must be > 0 and noise >= 0";
  if (!(time_limit > 0)) return "time_limit must be > 0";
  const int nq = models.planner->robot().nq;
  for (const auto& t : tasks) {
    if (t.goal.size() != nq || (t.retreat.size() != 0 && t.retreat.size() != nq)) {
      return "task '" + t.name + "' does not have one position per robot joint";
    }
  }
  return "";
}

void CalibrateBaselines(const intent::SkeletonDataset& demonstrations, BenchmarkSetup* setup) {
  if (!setup->intent_model || !setup->models.body) throw std::invalid_argument("CalibrateBaselines: no model or body");
  const auto& config = setup->intent_model->config;
  for (intent::BaselinePredictorParams* p : {&setup->constant_position, &setup->constant_velocity}) {
    p->rate = config.rate;
    p->horizon = config.horizon;
    p->joint_growth.clear();
    p->joint_growth = intent::CalibrateBaselineGrowth(*p, demonstrations, setup->models.body->params().joints);
  }
}

std::vector<ScenarioSpec> MakeScenarios(const BenchmarkSetup& setup, int count, uint64_t seed, Suite suite) {
  if (const std::string why = setup.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (count < 1) throw std::invalid_argument("the number of scenarios must be >= 1, got " + std::to_string(count));
  if (suite == Suite::kSharedSpace) return MakeSharedSpaceScenarios(setup, count, seed);
  const planning::Planner& planner = *setup.models.planner;
  const std::vector<NamedPose> poses = GraphPoses(setup.tasks);

  // Recorded sequences per subject, in file order.
  std::vector<std::string> subjects;
  std::map<std::string, std::vector<const intent::SkeletonSequence*>> by_subject;
  for (const auto& s : setup.recordings->sequences) {
    if (!Usable(*setup.recordings, s)) continue;
    if (!by_subject.count(s.subject)) subjects.push_back(s.subject);
    by_subject[s.subject].push_back(&s);
  }
  if (subjects.empty()) throw std::invalid_argument(setup.recordings_file + ": no sequence shows every joint");

  // Reaches keep the orientation the arm has at the first graph pose (for
  // the cell: home, the flange pointing down), turned about the vertical.
  const auto home_it = std::find_if(poses.begin(), poses.end(), [](const NamedPose& p) { return p.name == "home"; });
  const Eigen::VectorXd home = home_it != poses.end() ? home_it->q : poses.front().q;
  const Eigen::Matrix3d R_home = EndEffectorPose(planner, home).linear();

  std::string script;
  for (const auto& s : setup.person.script) script += (script.empty() ? "" : ",") + s.action;

  std::vector<ScenarioSpec> out;
  int recorded = 0;
  for (int i = 0; i < count; ++i) {
    ScenarioSpec s;
    s.index = i;
    Draws d(Mix(seed) ^ Mix(0x5cea0000ULL + static_cast<uint64_t>(i)));
    s.seed = d.Next();
    const bool graph_task = i % 2 == 0;
    const bool from_recording = (i / 2) % 2 == 0;
    if (from_recording) {
      DrawRecordedPerson(subjects, by_subject, recorded++, &d, &s);
    } else {
      DrawSyntheticPerson(setup.person, script, &d, &s);
    }
    if (graph_task) {
      DrawGraphTask(setup.tasks, poses, &d, &s);
    } else {
      DrawReach(planner, poses, home, R_home, &d, &s);
    }
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<InteractionResult> RunScenario(const BenchmarkSetup& setup, const ScenarioSpec& spec,
                                           const std::vector<Predictor>& predictors) {
  if (const std::string why = setup.Validate(); !why.empty()) throw std::invalid_argument(why);
  const intent::IntentModel& model = *setup.intent_model;
  // Long enough for the longest run and the oracle's look-ahead past it.
  const double duration = setup.loop.task_start + setup.loop.max_duration + model.config.horizon / model.config.rate + 1.0;
  const PersonStream person = MakePersonStream(setup, spec, duration);

  ModelTrack track(setup, person);
  const TrueCovariances true_covariance(setup, &track);

  TaskSetup task;
  task.start_q = spec.start_q;
  task.task.id = static_cast<uint32_t>(spec.index + 1);
  task.task.name = spec.task;
  task.task.goal = planning::Goal::Joint(spec.goal_q);
  task.task.retreat = spec.retreat_q;
  task.task.time_limit = setup.time_limit;

  std::vector<InteractionResult> results;
  for (Predictor p : predictors) {
    const PredictorSources sources(setup, person, &track, p);
    results.push_back(RunInteraction(setup.models, setup.loop, task, person, sources.planner(), sources.monitor(),
                                     true_covariance.source()));
  }
  return results;
}

Spread SpreadOf(std::vector<double> values) {
  Spread s;
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  s.median = core::QuantileSorted(values, 0.5);
  s.p10 = core::QuantileSorted(values, 0.1);
  s.p90 = core::QuantileSorted(values, 0.9);
  return s;
}

std::vector<PredictorSummary> Summarize(const std::vector<Predictor>& predictors,
                                        const std::vector<std::vector<InteractionResult>>& results) {
  const auto none_it = std::find(predictors.begin(), predictors.end(), Predictor::kNone);
  const std::ptrdiff_t none = none_it == predictors.end() ? -1 : none_it - predictors.begin();
  auto ratio = [](double a, double b) {
    return b > 0 ? a / b : (a > 0 ? std::numeric_limits<double>::infinity() : 0.0);
  };
  std::vector<PredictorSummary> out;
  for (std::size_t p = 0; p < predictors.size(); ++p) {
    PredictorSummary s;
    s.predictor = predictors[p];
    std::vector<double> time, stops, stop_time, separation, bound, time_ratio;
    double none_stops = 0, none_stop_time = 0;
    std::vector<double> none_time;
    for (const auto& scenario : results) {
      const InteractionResult& r = scenario.at(p);
      ++s.scenarios;
      if (r.finished && r.status == trajopt::TaskStatus::kSucceeded) ++s.succeeded;
      time.push_back(r.task_time);
      stops.push_back(r.protective_stops);
      s.protective_stops_total += r.protective_stops;
      s.stops_separation_total += r.stops_separation;
      s.stops_bound_total += r.stops_bound;
      stop_time.push_back(r.stop_time);
      s.stop_time_total += r.stop_time;
      s.slow_downs_total += r.slow_downs;
      s.slow_time_total += r.slow_time;
      separation.push_back(r.min_separation);
      bound.push_back(r.max_bound);
      s.true_contacts += r.true_contacts;
      s.robot_moving_contacts += r.robot_moving_contacts;
      s.robot_at_rest_contacts += r.robot_at_rest_contacts;
      if (none >= 0) {
        const InteractionResult& n = scenario.at(static_cast<std::size_t>(none));
        time_ratio.push_back(ratio(r.task_time, n.task_time));
        none_time.push_back(n.task_time);
        none_stops += n.protective_stops;
        none_stop_time += n.stop_time;
      }
    }
    s.task_time = SpreadOf(time);
    s.protective_stops = SpreadOf(stops);
    s.stop_time = SpreadOf(stop_time);
    s.min_separation = SpreadOf(separation);
    s.max_bound = SpreadOf(bound);
    if (none >= 0) {
      s.has_reference = true;
      s.task_time_ratio = SpreadOf(time_ratio);
      s.task_time_median_ratio = ratio(s.task_time.median, SpreadOf(none_time).median);
      s.protective_stops_ratio = ratio(s.protective_stops_total, none_stops);
      s.stop_time_ratio = ratio(s.stop_time_total, none_stop_time);
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace iplan::cell_sim

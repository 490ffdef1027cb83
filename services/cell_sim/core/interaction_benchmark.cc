#include "core/interaction_benchmark.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>

#include "core/person_motion.h"
#include "iplan/collision/robot_model.h"
#include "iplan/core/stats.h"

namespace iplan::cell_sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Scenario draws: a splitmix64 stream per scenario, so that scenario k is
// the same whatever the number of scenarios, and uniform numbers built from
// its bits (not std::uniform_*_distribution, whose output differs between
// standard libraries).
uint64_t Mix(uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

class Draws {
 public:
  explicit Draws(uint64_t seed) : state_(seed) {}
  uint64_t Next() { return Mix(state_++); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  int Index(std::size_t n) { return static_cast<int>(Next() % n); }

 private:
  uint64_t state_;
};

struct NamedPose {
  std::string name;
  Eigen::VectorXd q;
};

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


// The model's predictions of one scenario, made once (lazily, in frame
// order) and shared by every predictor's run: the estimator is fed every
// observed skeleton, as the intent service is.
class ModelTrack {
 public:
  ModelTrack(const BenchmarkSetup& setup, const PersonStream& person)
      : person_(person), estimator_(setup.intent_model, setup.estimator), joints_(setup.intent_model->config.joints.joints) {
    for (const auto& name : joints_) {
      const auto it = std::find(person.joint_names.begin(), person.joint_names.end(), name);
      if (it == person.joint_names.end()) {
        throw std::invalid_argument("the intent model's joint '" + name + "' is not a joint of the body model");
      }
      body_index_.push_back(static_cast<int>(it - person.joint_names.begin()));
    }
    frame_.body_id = 1;
    frame_.joints.resize(joints_.size());
    for (std::size_t j = 0; j < joints_.size(); ++j) frame_.joints[j].name = joints_[j];
  }

  const std::vector<std::string>& joints() const { return joints_; }
  int body_index(std::size_t model_joint) const { return body_index_[model_joint]; }

  const collision::JointMixture* At(int frame) {
    while (static_cast<int>(done_.size()) <= frame) Advance();
    return done_[static_cast<std::size_t>(frame)] ? &mixtures_[static_cast<std::size_t>(frame)] : nullptr;
  }
  // The model's within-action covariance sum_c p_c Sigma_c at (step, model joint).
  Eigen::Matrix3d WithinCovariance(int frame, int step, std::size_t joint) {
    const collision::JointMixture* m = At(frame);
    Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
    if (!m) return c;
    const std::size_t J = joints_.size();
    for (std::size_t a = 0; a < m->actions.size(); ++a) {
      c += m->probabilities[a] * m->covariances[a][static_cast<std::size_t>(step) * J + joint];
    }
    return c;
  }

 private:
  void Advance() {
    const int i = static_cast<int>(done_.size());
    const Eigen::Matrix3Xd& seen = person_.observed[static_cast<std::size_t>(i)];
    const int64_t t0 = SimTimeNs(person_.stamp(i));
    frame_.stamp = static_cast<double>(t0) * 1e-9;
    for (std::size_t j = 0; j < joints_.size(); ++j) frame_.joints[j].position = seen.col(body_index_[j]);
    const intent_service::FrameResult r = estimator_.Update(frame_, &mixture_);
    mixtures_.push_back(r.accepted() ? ToJointMixture(mixture_, joints_, t0) : collision::JointMixture{});
    done_.push_back(r.accepted());
  }

  const PersonStream& person_;
  intent_service::IntentEstimator estimator_;
  std::vector<std::string> joints_;
  std::vector<int> body_index_;
  intent_service::SkeletonFrame frame_;
  intent::MixturePrediction mixture_;
  std::vector<collision::JointMixture> mixtures_;
  std::vector<bool> done_;
};

// A baseline fed every observed skeleton in order; repeated requests for
// the same frame get the same prediction.
class BaselineSource {
 public:
  BaselineSource(intent::BaselinePredictorParams params, const PersonStream& person)
      : person_(person), predictor_(params, static_cast<int>(person.joint_names.size())) {}

  const collision::JointMixture* At(int frame) {
    while (last_ < frame) {
      ++last_;
      const Eigen::Matrix3Xd& seen = person_.observed[static_cast<std::size_t>(last_)];
      const Eigen::VectorXd p = Eigen::Map<const Eigen::VectorXd>(seen.data(), seen.size());
      predictor_.Update(person_.stamp(last_), p, &mixture_);
      current_ = ToJointMixture(mixture_, person_.joint_names, SimTimeNs(person_.stamp(last_)));
    }
    return last_ == frame ? &current_ : nullptr;
  }

 private:
  const PersonStream& person_;
  intent::BaselinePredictor predictor_;
  intent::MixturePrediction mixture_;
  collision::JointMixture current_;
  int last_ = -1;
};

// The true future at the model's steps with the model's within-action
// covariances.
class OracleSource {
 public:
  OracleSource(const PersonStream& person, ModelTrack* model, const intent::IntentModel& config)
      : person_(person), model_(model), dt_(1.0 / config.config.rate), steps_(config.config.horizon) {}

  const collision::JointMixture* At(int frame) {
    if (frame == frame_) return &current_;
    if (!model_->At(frame)) return nullptr;
    frame_ = frame;
    const std::size_t J = model_->joints().size();
    current_ = collision::JointMixture{};
    current_.t0_ns = SimTimeNs(person_.stamp(frame));
    current_.time_step = dt_;
    current_.num_steps = steps_;
    current_.joint_names = model_->joints();
    current_.actions = {"oracle"};
    current_.probabilities = {1.0};
    current_.means.assign(1, std::vector<Eigen::Vector3d>(static_cast<std::size_t>(steps_) * J));
    current_.covariances.assign(1, std::vector<Eigen::Matrix3d>(static_cast<std::size_t>(steps_) * J));
    for (int k = 0; k < steps_; ++k) {
      person_.TrueAt(person_.stamp(frame) + (k + 1) * dt_, &p_WJ_);
      for (std::size_t j = 0; j < J; ++j) {
        const std::size_t o = static_cast<std::size_t>(k) * J + j;
        current_.means[0][o] = p_WJ_.col(model_->body_index(j));
        current_.covariances[0][o] = model_->WithinCovariance(frame, k, j);
      }
    }
    return &current_;
  }

 private:
  const PersonStream& person_;
  ModelTrack* model_;
  double dt_;
  int steps_;
  int frame_ = -1;
  collision::JointMixture current_;
  Eigen::Matrix3Xd p_WJ_;
};

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

// ---- The shared-space suite ----

// What every shared-space draw needs from the setup.
struct SharedSpaceCell {
  const BenchmarkSetup* setup = nullptr;
  const planning::Planner* planner = nullptr;
  std::vector<NamedPose> poses;
  Eigen::VectorXd home;
  Eigen::Matrix3d R_home;
  const GraphTask* hand_over = nullptr;
  const GraphTask* fetch_left = nullptr;
  const perception::ActionMotion* reach_parts = nullptr;  // the person's reach into the parts tray
  const perception::ActionMotion* assemble = nullptr;     // the person's work at the assembly area
  perception::ActionMotion rest;                          // what the person does before and after
  bool rest_is_cells = false;                             // rest is one of the cell's actions
  std::string script;                                     // the cell's script, comma-separated
  std::vector<std::string> subjects;
  std::map<std::string, std::vector<const intent::SkeletonSequence*>> by_subject;
};

// The flange point at q (the reach's target point), W.
Eigen::Vector3d FlangePoint(const planning::Planner& planner, const Eigen::VectorXd& q) {
  return EndEffectorPose(planner, q).translation();
}

std::string Join(const std::vector<perception::ScriptStep>& script) {
  std::string out;
  for (const auto& s : script) out += (out.empty() ? "" : ",") + s.action;
  return out;
}

// The synthetic person placed with its torso at torso_W (turned by yaw from
// the configured facing): which hand is on the side of p_W.
bool RightHandTowards(const perception::SyntheticPersonParams& person, double yaw, const Eigen::Vector3d& torso_W,
                      const Eigen::Vector3d& p_W) {
  // The person frame's y is to their left.
  const Eigen::Vector3d left_W =
      Eigen::AngleAxisd(person.facing_yaw + yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * Eigen::Vector3d::UnitY();
  return (p_W - torso_W).dot(left_W) < 0;
}

// The synthetic person at torso_W doing `action` (replacing the cell's of
// its name or added to them) from script_start for `seconds`, then resting.
void SharedSynthetic(const SharedSpaceCell& c, const Eigen::Vector3d& torso_W, double yaw, double script_start,
                     const perception::ActionMotion& action, double seconds, ScenarioSpec* s) {
  s->source = "synthetic";
  s->subject = "synthetic";
  s->placement_W = torso_W;
  s->yaw = yaw;
  s->delay = script_start;
  s->person_actions = {action};
  if (!c.rest_is_cells) s->person_actions.push_back(c.rest);
  s->person_script = {{action.name, seconds}, {c.rest.name, 1.0}};
  s->sequence = Join(s->person_script);
}

// A recorded person whose hands' farthest reach towards the robot (smallest
// x over both hands, in the task's first `window` s) falls on target_W
// (horizontally; shoulders at the synthetic person's height, no nearer the
// robot than x = 1.0 m, the table's far edge being at 1.05 m).
void SharedRecorded(const SharedSpaceCell& c, int recorded, const Eigen::Vector3d& target_W, Draws* d,
                    ScenarioSpec* s) {
  const BenchmarkSetup& setup = *c.setup;
  DrawRecordedPerson(c.subjects, c.by_subject, recorded, d, s);  // subject, sequence, yaw, clip, delay
  const double t0 = setup.loop.task_start, t1 = t0 + setup.shared_space.window;
  const PersonStream provisional = MakePersonStream(setup, *s, t1 + 0.1);
  const auto& joints = setup.models.body->params().joints;
  std::vector<Eigen::Index> hands;
  for (const char* h : {"hand_l", "hand_r"}) {
    const auto it = std::find(joints.begin(), joints.end(), h);
    if (it != joints.end()) hands.push_back(it - joints.begin());
  }
  if (hands.empty()) throw std::invalid_argument("the shared-space suite needs the body joints hand_l or hand_r");
  Eigen::Vector3d reach(std::numeric_limits<double>::infinity(), 0.0, 0.0);
  for (int f = 0; f < provisional.num_frames(); ++f) {
    if (provisional.stamp(f) < t0 || provisional.stamp(f) > t1) continue;
    for (Eigen::Index h : hands) {
      const Eigen::Vector3d p = provisional.truth[static_cast<std::size_t>(f)].col(h);
      if (p.x() < reach.x()) reach = p;
    }
  }
  const Eigen::Vector3d shift(target_W.x() - reach.x(), target_W.y() - reach.y(), 0.0);
  s->placement_W += shift;
  s->placement_W.x() = std::max(s->placement_W.x(), 1.0);
}

// A reach whose flange target lies in box [lo, hi] (W, m), from a graph
// pose, as DrawReach; false when none of 20 tries is reachable and clear.
bool SharedReach(const SharedSpaceCell& c, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, Draws* d,
                 ScenarioSpec* s) {
  const planning::Planner& planner = *c.planner;
  s->task = "reach";
  const NamedPose& start = c.poses[static_cast<std::size_t>(d->Index(c.poses.size()))];
  s->start = start.name;
  s->start_q = start.q;
  for (int attempt = 0; attempt < 20; ++attempt) {
    const Eigen::Vector3d p(d->Uniform(lo.x(), hi.x()), d->Uniform(lo.y(), hi.y()), d->Uniform(lo.z(), hi.z()));
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(d->Uniform(-0.5, 0.5), Eigen::Vector3d::UnitZ()).toRotationMatrix() * c.R_home;
    const planning::IkResult ik = planner.SolveIk(p, Eigen::Quaterniond(R), c.home, d->Next());
    if (!ik.success) continue;
    if (planner.CalcClearance(ik.q) < planner.params().min_clearance + 0.02) continue;
    if ((ik.q - s->start_q).cwiseAbs().maxCoeff() < 0.3) continue;
    s->goal_q = ik.q;
    s->reach_p_WE = p;
    return true;
  }
  return false;
}

// The flange points along the straight joint path from start to goal at
// fractions u in [0.2, 0.8] (13 of them).
std::vector<Eigen::Vector3d> PathPoints(const planning::Planner& planner, const ScenarioSpec& s) {
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k <= 12; ++k) {
    const double u = 0.2 + 0.05 * k;
    points.push_back(FlangePoint(planner, s.start_q + u * (s.goal_q - s.start_q)));
  }
  return points;
}

// One draw of scenario s->index of `kind` (index into SharedSpaceKinds()),
// its person synthetic or recorded; false when the draw is unusable (a
// reach not found, a path the person cannot cross).
bool DrawShared(const SharedSpaceCell& c, int kind, bool synthetic, int recorded, Draws* d, ScenarioSpec* s) {
  const BenchmarkSetup& setup = *c.setup;
  const planning::Planner& planner = *c.planner;
  const perception::SyntheticPersonParams& person = setup.person;
  const double yaw = d->Uniform(-0.2, 0.2);
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  // where the person's hand is to go
  switch (kind) {
    case 0: {  // hand-over: the person reaches for the part in the tool, just in front of and below the flange
      DrawGraphTask({*c.hand_over}, c.poses, d, s);
      s->shared_point_W = FlangePoint(planner, s->goal_q);
      target = s->shared_point_W + Eigen::Vector3d(d->Uniform(0.06, 0.16), d->Uniform(-0.05, 0.05), d->Uniform(-0.10, -0.02));
      if (synthetic) {
        const Eigen::Vector3d torso = person.torso_W + Eigen::Vector3d(d->Uniform(-0.15, -0.05), d->Uniform(-0.15, 0.05), 0.0);
        perception::ActionMotion a;
        a.name = "reach_hand_over";
        a.kind = perception::MotionKind::kReach;
        a.right_hand = RightHandTowards(person, yaw, torso, target);
        a.target_W = target;
        a.period = d->Uniform(2.5, 3.5);
        SharedSynthetic(c, torso, yaw, d->Uniform(0.0, 2.5), a, 2 * a.period, s);
      }
      break;
    }
    case 1: {  // parts-bin: into the bin under fetch_left's flange, or between it and the tray
      DrawGraphTask({*c.fetch_left}, c.poses, d, s);
      const Eigen::Vector3d flange = FlangePoint(planner, s->goal_q);
      const Eigen::Vector3d tray = c.reach_parts->target_W;
      const Eigen::Vector3d bin(flange.x(), flange.y(), tray.z() + 0.05);
      target = tray + d->Uniform(0.3, 1.0) * (bin - tray);
      s->shared_point_W = target;
      if (synthetic) {
        const Eigen::Vector3d torso = person.torso_W + Eigen::Vector3d(d->Uniform(-0.20, -0.08), d->Uniform(0.0, 0.15), 0.0);
        perception::ActionMotion a = *c.reach_parts;
        a.right_hand = RightHandTowards(person, yaw, torso, target);
        a.target_W = target;
        SharedSynthetic(c, torso, yaw, d->Uniform(0.0, 2.5), a, 2 * a.period, s);
      }
      break;
    }
    case 2: {  // co-assembly: the robot reaches to the near side of the person's assembly area
      if (!SharedReach(c, {0.60, -0.12, 0.24}, {0.72, 0.12, 0.34}, d, s)) return false;
      s->shared_point_W = s->reach_p_WE;
      target = Eigen::Vector3d(s->reach_p_WE.x() + d->Uniform(0.14, 0.24), s->reach_p_WE.y() + d->Uniform(-0.06, 0.06),
                               c.assemble->target_W.z());
      if (synthetic) {
        const Eigen::Vector3d torso =
            person.torso_W + Eigen::Vector3d(d->Uniform(-0.15, -0.05),
                                             target.y() - c.assemble->target_W.y() + d->Uniform(-0.05, 0.05), 0.0);
        perception::ActionMotion a = *c.assemble;
        a.target_W = target;
        // Assembling when the robot arrives (it is commanded at task_start),
        // for 3-6 s, then resting.
        SharedSynthetic(c, torso, yaw, d->Uniform(-2.0, 1.5), a, d->Uniform(3.0, 6.0), s);
      }
      break;
    }
    default: {  // crossing: the hand sweeps across the path's point nearest the person, mid-task
      DrawGraphTask(setup.tasks, c.poses, d, s);
      const std::vector<Eigen::Vector3d> points = PathPoints(planner, *s);
      std::size_t k = 0;
      for (std::size_t i = 1; i < points.size(); ++i) {
        if (points[i].x() > points[k].x()) k = i;
      }
      const Eigen::Vector3d crossing = points[k];
      if (crossing.x() < 0.40) return false;  // the path stays by the robot, out of the person's reach
      s->shared_point_W = crossing;
      target = crossing;
      if (synthetic) {
        const Eigen::Vector3d along = points[std::min(k + 1, points.size() - 1)] - points[k > 0 ? k - 1 : 0];
        Eigen::Vector3d side = Eigen::Vector3d::UnitZ().cross(along);
        side = side.norm() > 1e-6 ? Eigen::Vector3d(side.normalized()) : Eigen::Vector3d::UnitY();
        const Eigen::Vector3d torso(std::max(crossing.x() + d->Uniform(0.45, 0.55), 1.1),
                                    crossing.y() + d->Uniform(-0.15, 0.15), person.torso_W.z());
        HandSweep w;
        const double half = d->Uniform(0.18, 0.28) * (d->Uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0);
        const Eigen::Vector3d lift(0, 0, d->Uniform(-0.04, 0.04));
        w.from_W = crossing + half * side + lift;
        w.to_W = crossing - half * side + lift;
        w.from_W.z() = std::max(w.from_W.z(), 0.08);
        w.to_W.z() = std::max(w.to_W.z(), 0.08);
        w.right_hand = RightHandTowards(person, yaw, torso, crossing);
        w.duration = d->Uniform(0.8, 1.4);
        w.approach = 0.6;
        w.start = setup.loop.task_start + d->Uniform(0.6, 2.2) - w.approach - 0.5 * w.duration;
        s->source = "synthetic";
        s->subject = "synthetic";
        s->placement_W = torso;
        s->yaw = yaw;
        s->delay = d->Uniform(-9.0, 2.0);  // the person's own script goes on, as in the default suite
        s->sequence = c.script;
        s->sweep = w;
      }
      break;
    }
  }
  // A recorded person's hands stay near their farthest reach much of the
  // time: it is put 0.10-0.25 m beyond the shared point (towards the
  // person), so that they come within reach of the path without holding its
  // goal for good.
  if (!synthetic) SharedRecorded(c, recorded, target + Eigen::Vector3d(d->Uniform(0.10, 0.25), 0.0, 0.0), d, s);
  return true;
}

std::vector<ScenarioSpec> MakeSharedSpaceScenarios(const BenchmarkSetup& setup, int count, uint64_t seed) {
  if (const std::string why = setup.shared_space.Validate(); !why.empty()) {
    throw std::invalid_argument("shared-space suite: " + why);
  }
  SharedSpaceCell c;
  c.setup = &setup;
  c.planner = setup.models.planner;
  c.poses = GraphPoses(setup.tasks);
  for (const auto& t : setup.tasks) {
    if (t.name == "hand_over") c.hand_over = &t;
    if (t.name == "fetch_left") c.fetch_left = &t;
  }
  if (!c.hand_over || !c.fetch_left) {
    throw std::invalid_argument("the shared-space suite needs the task graph's 'hand_over' and 'fetch_left' tasks");
  }
  for (const auto& a : setup.person.actions) {
    if (a.name == "reach_parts" && a.kind == perception::MotionKind::kReach) c.reach_parts = &a;
    if (a.name == "assemble" && a.kind == perception::MotionKind::kWork) c.assemble = &a;
    if (a.kind == perception::MotionKind::kRest && !c.rest_is_cells) {
      c.rest = a;
      c.rest_is_cells = true;
    }
  }
  if (!c.reach_parts || !c.assemble) {
    throw std::invalid_argument(
        "the shared-space suite needs the synthetic person's 'reach_parts' (motion reach) and 'assemble' (motion work) "
        "actions");
  }
  if (!c.rest_is_cells) {
    c.rest.name = "idle";
    c.rest.kind = perception::MotionKind::kRest;
    c.rest.period = 3.0;
    c.rest.amplitude = 0.02;
  }
  for (const auto& s : setup.person.script) c.script += (c.script.empty() ? "" : ",") + s.action;
  if (c.script.empty()) c.script = setup.person.actions.front().name;
  const auto home_it = std::find_if(c.poses.begin(), c.poses.end(), [](const NamedPose& p) { return p.name == "home"; });
  c.home = home_it != c.poses.end() ? home_it->q : c.poses.front().q;
  c.R_home = EndEffectorPose(*c.planner, c.home).linear();
  for (const auto& s : setup.recordings->sequences) {
    if (!Usable(*setup.recordings, s)) continue;
    if (!c.by_subject.count(s.subject)) c.subjects.push_back(s.subject);
    c.by_subject[s.subject].push_back(&s);
  }
  if (c.subjects.empty()) throw std::invalid_argument(setup.recordings_file + ": no sequence shows every joint");

  const int kinds = static_cast<int>(SharedSpaceKinds().size());
  const double limit = setup.shared_space.max_path_distance;
  std::vector<ScenarioSpec> out;
  for (int i = 0; i < count; ++i) {
    const int kind = i % kinds;
    const bool synthetic = (i / kinds) % 2 == 0;
    // Recorded scenarios (the second block of four in every eight) take the
    // subjects in turn, shifted by one every eight so that with two subjects
    // each kind gets both.
    const int recorded = (i / (2 * kinds)) * (kinds + 1) + kind;
    Draws d(Mix(seed) ^ Mix(0x5ba4e0000ULL + static_cast<uint64_t>(i)));
    const uint64_t noise_seed = d.Next();
    double nearest = std::numeric_limits<double>::infinity();
    bool kept = false;
    for (int draw = 1; draw <= setup.shared_space.max_draws && !kept; ++draw) {
      ScenarioSpec s;
      s.index = i;
      s.seed = noise_seed;
      s.kind = SharedSpaceKinds()[static_cast<std::size_t>(kind)];
      s.draws = draw;
      if (!DrawShared(c, kind, synthetic, recorded, &d, &s)) continue;
      const double distance = ScenarioPathDistance(setup, s);
      nearest = std::min(nearest, distance);
      if (!(distance < limit)) continue;
      s.path_distance = distance;
      out.push_back(std::move(s));
      kept = true;
    }
    if (!kept) {
      throw std::runtime_error("shared-space scenario " + std::to_string(i) + " (" +
                               SharedSpaceKinds()[static_cast<std::size_t>(kind)] + "): no draw of " +
                               std::to_string(setup.shared_space.max_draws) + " brought the person within " +
                               std::to_string(limit) + " m of the robot's path (nearest " + std::to_string(nearest) +
                               " m)");
    }
  }
  return out;
}

}  // namespace

collision::JointMixture ToJointMixture(const intent::MixturePrediction& m, const std::vector<std::string>& joints,
                                       int64_t t0_ns) {
  collision::JointMixture out;
  out.t0_ns = t0_ns;
  out.time_step = m.dt;
  out.num_steps = m.horizon;
  out.joint_names = joints;
  for (const auto& a : m.actions) {
    out.actions.push_back(a.action);
    out.probabilities.push_back(a.probability);
    std::vector<Eigen::Vector3d> means;
    std::vector<Eigen::Matrix3d> covs;
    means.reserve(a.joints.size());
    covs.reserve(a.joints.size());
    for (const auto& g : a.joints) {
      means.push_back(g.mean);
      covs.push_back(g.covariance);
    }
    out.means.push_back(std::move(means));
    out.covariances.push_back(std::move(covs));
  }
  return out;
}

const char* ToString(Predictor p) {
  switch (p) {
    case Predictor::kNone: return "none";
    case Predictor::kConstantPosition: return "constant-position";
    case Predictor::kConstantVelocity: return "constant-velocity";
    case Predictor::kModel: return "model";
    case Predictor::kOracle: return "oracle";
  }
  return "unknown";
}

std::vector<std::string> PredictorNames() {
  std::vector<std::string> names;
  for (Predictor p : {Predictor::kNone, Predictor::kConstantPosition, Predictor::kConstantVelocity, Predictor::kModel,
                      Predictor::kOracle}) {
    names.push_back(ToString(p));
  }
  return names;
}

std::optional<Predictor> ParsePredictor(const std::string& name) {
  for (Predictor p : {Predictor::kNone, Predictor::kConstantPosition, Predictor::kConstantVelocity, Predictor::kModel,
                      Predictor::kOracle}) {
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

const std::vector<std::string>& SharedSpaceKinds() {
  static const std::vector<std::string> kKinds = {"hand-over", "parts-bin", "co-assembly", "crossing"};
  return kKinds;
}

std::string SharedSpaceParams::Validate() const {
  if (!(max_path_distance > 0) || !std::isfinite(max_path_distance)) {
    return "max_path_distance must be > 0 m, got " + std::to_string(max_path_distance);
  }
  if (!(window > 0) || !std::isfinite(window)) return "window must be > 0 s, got " + std::to_string(window);
  if (path_samples < 2) return "path_samples must be >= 2, got " + std::to_string(path_samples);
  if (max_draws < 1) return "max_draws must be >= 1, got " + std::to_string(max_draws);
  return "";
}

double PathDistance(const collision::RobotModel& robot, const collision::HumanBodyModel& body,
                    const Eigen::VectorXd& start_q, const Eigen::VectorXd& goal_q, int samples,
                    const PersonStream& person, double t0, double t1) {
  if (start_q.size() != robot.nq || goal_q.size() != robot.nq) {
    throw std::invalid_argument("PathDistance: start and goal need " + std::to_string(robot.nq) + " joint positions");
  }
  if (samples < 2) throw std::invalid_argument("PathDistance: samples must be >= 2, got " + std::to_string(samples));
  if (person.joint_names != body.params().joints) {
    throw std::invalid_argument("PathDistance: the person's joints are not the body model's, in its order");
  }
  if (!(t1 >= t0)) throw std::invalid_argument("PathDistance: the window ends before it starts");
  // The robot's spheres along the path, once.
  collision::RobotData data(robot);
  const std::size_t K = robot.spheres.size();
  std::vector<Eigen::Vector3d> centres;
  centres.reserve(static_cast<std::size_t>(samples) * K);
  for (int k = 0; k < samples; ++k) {
    const double u = static_cast<double>(k) / (samples - 1);
    collision::CalcForwardKinematics(robot, start_q + u * (goal_q - start_q), &data);
    for (std::size_t j = 0; j < K; ++j) centres.push_back(data.p_WS.col(static_cast<Eigen::Index>(j)));
  }
  double best = std::numeric_limits<double>::infinity();
  int frames = 0;
  for (int f = 0; f < person.num_frames(); ++f) {
    if (person.stamp(f) < t0 || person.stamp(f) > t1) continue;
    ++frames;
    const Eigen::Matrix3Xd& joints = person.truth[static_cast<std::size_t>(f)];
    for (int h = 0; h < body.num_spheres(); ++h) {
      const Eigen::Vector3d c = body.SphereCentre(h, joints);
      const double r = body.spheres()[static_cast<std::size_t>(h)].radius;
      for (std::size_t i = 0; i < centres.size(); ++i) {
        best = std::min(best, (centres[i] - c).norm() - robot.spheres[i % K].radius - r);
      }
    }
  }
  if (frames == 0) throw std::invalid_argument("PathDistance: no frame of the person in the window");
  return best;
}

double ScenarioPathDistance(const BenchmarkSetup& setup, const ScenarioSpec& spec) {
  const double t0 = setup.loop.task_start, t1 = t0 + setup.shared_space.window;
  const PersonStream person = MakePersonStream(setup, spec, t1 + 0.1);
  return PathDistance(setup.models.planner->robot(), *setup.models.body, spec.start_q, spec.goal_q,
                      setup.shared_space.path_samples, person, t0, t1);
}

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
  const std::vector<std::string>& body_joints = setup.models.body->params().joints;
  // Long enough for the longest run and the oracle's look-ahead past it.
  const double duration = setup.loop.task_start + setup.loop.max_duration + model.config.horizon / model.config.rate + 1.0;
  const PersonStream person = MakePersonStream(setup, spec, duration);

  ModelTrack track(setup, person);
  const PredictionSource model_source = [&track](int f) { return track.At(f); };
  // The true bound's covariances: the model's first step, in body order.
  std::vector<Eigen::Matrix3d> covs(body_joints.size());
  int covs_frame = -1;
  const CovarianceSource true_covariance = [&](int f) -> const std::vector<Eigen::Matrix3d>* {
    if (!track.At(f)) return nullptr;
    if (f != covs_frame) {
      const Eigen::Matrix3d fallback =
          setup.loop.true_bound_std * setup.loop.true_bound_std * Eigen::Matrix3d::Identity();
      std::fill(covs.begin(), covs.end(), fallback);
      for (std::size_t j = 0; j < track.joints().size(); ++j) {
        covs[static_cast<std::size_t>(track.body_index(j))] = track.WithinCovariance(f, 0, j);
      }
      covs_frame = f;
    }
    return &covs;
  };

  TaskSetup task;
  task.start_q = spec.start_q;
  task.task.id = static_cast<uint32_t>(spec.index + 1);
  task.task.name = spec.task;
  task.task.goal = planning::Goal::Joint(spec.goal_q);
  task.task.retreat = spec.retreat_q;
  task.task.time_limit = setup.time_limit;

  std::vector<InteractionResult> results;
  for (Predictor p : predictors) {
    std::optional<BaselineSource> baseline;
    std::optional<OracleSource> oracle;
    PredictionSource planner_source;
    switch (p) {
      case Predictor::kNone:
        break;
      case Predictor::kConstantPosition:
      case Predictor::kConstantVelocity: {
        intent::BaselinePredictorParams bp =
            p == Predictor::kConstantPosition ? setup.constant_position : setup.constant_velocity;
        bp.rate = model.config.rate;
        bp.horizon = model.config.horizon;
        baseline.emplace(bp, person);
        planner_source = [&baseline](int f) { return baseline->At(f); };
        break;
      }
      case Predictor::kModel:
        planner_source = model_source;
        break;
      case Predictor::kOracle:
        oracle.emplace(person, &track, model);
        planner_source = [&oracle](int f) { return oracle->At(f); };
        break;
    }
    const bool own = setup.monitor_input == MonitorInput::kSame && p != Predictor::kNone;
    const PredictionSource& monitor_source = own ? planner_source : model_source;
    results.push_back(RunInteraction(setup.models, setup.loop, task, person, planner_source, monitor_source, true_covariance));
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

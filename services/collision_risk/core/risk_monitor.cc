#include "risk_monitor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <stdexcept>

namespace iplan::collision_risk {
namespace {

std::string Fmt(double v, const char* f = "%.3g") {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

}  // namespace

std::string RiskParams::Validate() const {
  if (!(delta_cl > 0 && delta_cl < 1)) return "delta_cl must be in (0, 1)";
  if (!(stop_horizon >= 0)) return "stop_horizon must be >= 0";
  if (!(slow_down_fraction > 0 && slow_down_fraction <= 1)) return "slow_down_fraction must be in (0, 1]";
  if (!(slow_down_margin >= 0)) return "slow_down_margin must be >= 0";
  if (!(bound_retreat_gain >= 0 && bound_retreat_gain <= 1)) return "bound_retreat_gain must be in [0, 1]";
  if (!(stale_after > 0)) return "stale_after must be > 0";
  if (!(joint_limit_tolerance >= 0)) return "joint_limit_tolerance must be >= 0";
  if (std::string why = ssm.Validate(); !why.empty()) return why;
  return human_points.Validate();
}

RiskMonitor::RiskMonitor(collision::RobotModel robot, collision::HumanBodyParams body, RiskParams params)
    : robot_(std::move(robot)),
      robot_joints_(robot_.JointNames()),
      body_(std::move(body)),
      params_(params),
      data_(robot_),
      data2_(robot_),
      workspace_(static_cast<int>(robot_.spheres.size()), 0) {
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
  workspace_ = collision::TrajectoryBoundWorkspace(static_cast<int>(robot_.spheres.size()), body_.num_spheres());
}

std::optional<std::string> RiskMonitor::UpdateRobotState(int64_t stamp_ns, const std::vector<std::string>& names,
                                                         const std::vector<double>& positions) {
  if (names.size() != positions.size()) return std::string("names and positions differ in size");
  std::vector<int> idx;
  if (auto e = cell::MapJointNames(names, robot_joints_, &idx)) return "joint state: " + *e;
  Eigen::VectorXd q(robot_.nq);
  for (int i = 0; i < robot_.nq; ++i) q[i] = positions[static_cast<std::size_t>(idx[static_cast<std::size_t>(i)])];
  // A state the arm cannot be in is a wrong or corrupted measurement: the
  // robot's spheres placed from it would be nowhere near the real arm. Refused
  // (and counted), it ages into "robot state is stale", a protective stop.
  if (auto e = collision::CheckJointPositions(robot_, q, params_.joint_limit_tolerance)) return "joint state: " + *e;
  previous_state_ = state_;
  state_ = std::make_pair(stamp_ns, q);
  return std::nullopt;
}

std::optional<std::string> RiskMonitor::UpdateTrajectory(int64_t start_ns, const std::vector<std::string>& names,
                                                         const std::vector<double>& times,
                                                         const std::vector<std::vector<double>>& positions) {
  if (times.empty() && positions.empty()) {  // no trajectory: the robot holds its state
    trajectory_ = cell::JointTrajectory{};
    return std::nullopt;
  }
  if (auto e = cell::JointTrajectory::FromPoints(start_ns, names, times, positions, robot_joints_, &trajectory_))
    return "trajectory: " + *e;
  return std::nullopt;
}

std::optional<std::string> RiskMonitor::UpdateSkeleton(cell::BodyId body_id, int64_t stamp_ns,
                                                       const std::vector<std::string>& names,
                                                       const std::vector<Eigen::Vector3d>& positions) {
  std::vector<int> idx;
  if (auto e = cell::MapJointNames(names, body_.params().joints, &idx)) return "skeleton: " + *e;
  const int64_t keep = static_cast<int64_t>((params_.ssm.speed_window + params_.stale_after) * 1e9);
  skeletons_.Expire(stamp_ns, keep);  // people who left
  std::string why;
  SkeletonHistory* history = skeletons_.Touch(body_id, stamp_ns, &why);
  if (!history) return "skeleton: " + why;
  Eigen::Matrix3Xd p(3, body_.num_joints());
  for (int j = 0; j < body_.num_joints(); ++j) p.col(j) = positions[static_cast<std::size_t>(idx[static_cast<std::size_t>(j)])];
  history->emplace_back(stamp_ns, p);
  while (history->size() > 2 && stamp_ns - history->front().first > keep) history->pop_front();
  last_skeleton_ns_ = std::max(last_skeleton_ns_, stamp_ns);
  return std::nullopt;
}

std::optional<std::string> RiskMonitor::UpdatePrediction(cell::BodyId body_id, const PredictionInput& in) {
  return cell::KeepNewestPrediction(body_, body_id, in, params_.stale_after, &predictions_);
}

Eigen::VectorXd RiskMonitor::RobotConfigurationAt(int64_t t_ns) const {
  return trajectory_.empty() ? state_->second : trajectory_.PositionAt(t_ns);
}

bool RiskMonitor::MeasuredJointVelocities(const SkeletonHistory& history, Eigen::Matrix3Xd* v) const {
  if (!params_.ssm.measure_human_speed || history.size() < 2) return false;
  const auto& newest = history.back();
  const int64_t window = static_cast<int64_t>(params_.ssm.speed_window * 1e9);
  // The oldest skeleton still within the window, at least half a window back.
  for (const auto& s : history) {
    const int64_t dt = newest.first - s.first;
    if (dt <= window && dt >= window / 2) {
      *v = (newest.second - s.second) / (dt * 1e-9);
      return true;
    }
  }
  return false;  // not enough history
}

void RiskMonitor::RobotSphereVelocities(int64_t now_ns, Eigen::Matrix3Xd* v) {
  Eigen::VectorXd q0, q1;
  double dt = 0;
  if (!trajectory_.empty()) {
    dt = 0.02;
    q0 = RobotConfigurationAt(now_ns);
    q1 = RobotConfigurationAt(now_ns + static_cast<int64_t>(dt * 1e9));
  } else if (previous_state_ && state_->first > previous_state_->first) {
    dt = (state_->first - previous_state_->first) * 1e-9;
    q0 = previous_state_->second;
    q1 = state_->second;
  } else {
    v->setZero(3, static_cast<Eigen::Index>(robot_.spheres.size()));
    return;
  }
  collision::CalcForwardKinematics(robot_, q0, &data_);
  collision::CalcForwardKinematics(robot_, q1, &data2_);
  *v = (data2_.p_WS - data_.p_WS) / dt;
}

RiskReport RiskMonitor::Evaluate(int64_t now_ns) {
  RiskReport r;
  r.stamp_ns = now_ns;
  const int64_t stale = static_cast<int64_t>(params_.stale_after * 1e9);
  if (!state_ || now_ns - state_->first > stale) {
    r.verdict = Verdict::kProtectiveStop;
    r.reason = state_ ? "robot state is stale" : "no robot state yet";
    r.speed_scale = 0.0;
    return r;
  }
  Inputs in;
  in.stale_ns = stale;
  r.num_people = skeletons_.CountFresh(now_ns, stale);
  r.num_predicted = predictions_.CountFresh(now_ns, stale);
  in.person = r.num_people > 0;
  in.predicted = r.num_predicted > 0;
  // Degraded when someone seen has no fresh prediction of their own.
  for (const auto& [id, e] : skeletons_) {
    const auto* pred = predictions_.Find(id);
    if (now_ns - e.stamp_ns <= stale && (!pred || now_ns - pred->stamp_ns > stale))
      in.degraded = params_.ssm.degrade_without_prediction;
  }
  in.points = points_stamp_ns_ > 0 && now_ns - points_stamp_ns_ <= stale;
  r.trajectory_stamp_ns = trajectory_.empty() ? 0 : trajectory_.start_ns;
  EvaluateSeparation(now_ns, in, &r);
  if (!in.person && in.points) EvaluateSeparationFromPoints(now_ns, &r);
  if (in.predicted) {
    EvaluateBound(now_ns, &r);
  } else if (in.points) {
    EvaluateBoundFromPoints(now_ns, &r);
  }
  DecideVerdict(now_ns, in, &r);
  return r;
}

// ISO/TS 15066 layer: current separation against S_p, per sphere pair when
// directed (see the header), else one S_p from the fastest joint and the
// fastest robot sphere; the smallest over the persons seen.
struct RiskMonitor::SeparationSearch {
  double best = std::numeric_limits<double>::infinity(), best_margin = best;
  bool retreating = false;  // the binding pair is a retreat inside S_p
  double slow_scale = 1.0, stop_scale = 1.0;  // speed reduction: the smallest over the pairs
  std::size_t closest_k = 0, binding_k = 0;
  int closest_h = 0, binding_h = 0;
  cell::BodyId body = 0;  // the person searched now
};

void RiskMonitor::EvaluateSeparation(int64_t now_ns, const Inputs& in, RiskReport* out) {
  RiskReport& r = *out;
  const SsmParams& s = params_.ssm;
  Eigen::Matrix3Xd v_robot;
  RobotSphereVelocities(now_ns, &v_robot);
  // Undirected speeds of nobody (what is reported when nobody is seen).
  r.human_speed = s.default_human_speed;
  r.robot_speed = v_robot.cols() > 0 ? v_robot.colwise().norm().maxCoeff() : 0.0;
  r.protective_separation = safety::ProtectiveSeparationDistance(s, r.human_speed, r.robot_speed);
  if (!in.person) return;
  collision::CalcForwardKinematics(robot_, state_->second, &data_);
  SeparationSearch search;
  for (const auto& [id, e] : skeletons_) {
    if (now_ns - e.stamp_ns > in.stale_ns) continue;
    const auto* pred = predictions_.Find(id);
    const bool predicted = pred && now_ns - pred->stamp_ns <= in.stale_ns;
    // A person without a usable prediction is taken at the default speed.
    const bool degraded = !predicted && s.degrade_without_prediction;
    search.body = id;
    SearchPerson(e.value, !degraded, v_robot, &search, &r);
  }
  const auto& robot_spheres = robot_.spheres;
  auto link = [&](std::size_t k) { return robot_.link_names[static_cast<std::size_t>(robot_spheres[k].link)]; };
  auto segment = [&](int h) {
    return body_.params().segments[static_cast<std::size_t>(body_.spheres()[static_cast<std::size_t>(h)].segment)].name;
  };
  r.min_separation = search.best;
  r.separation_robot_link = link(search.closest_k);
  r.separation_human_segment = segment(search.closest_h);
  r.separation_margin = search.best_margin;
  r.retreating = search.retreating;
  r.stop_scale = search.stop_scale;
  if (s.speed_reduction && search.slow_scale < 1.0) r.speed_scale = std::max(s.min_speed_scale, search.slow_scale);
  r.binding_robot_link = link(search.binding_k);
  r.binding_human_segment = segment(search.binding_h);
}

// One person's sphere pairs: the closest and the binding (smallest margin
// to S_p) pair, when closer than the persons' so far.
void RiskMonitor::SearchPerson(const SkeletonHistory& history, bool may_measure, const Eigen::Matrix3Xd& v_robot,
                               SeparationSearch* search, RiskReport* out) const {
  RiskReport& r = *out;
  const SsmParams& s = params_.ssm;
  const auto& robot_spheres = robot_.spheres;
  Eigen::Matrix3Xd v_joints;
  const bool measured = may_measure && MeasuredJointVelocities(history, &v_joints);
  const double v_h_max = measured ? v_joints.colwise().norm().maxCoeff() : s.default_human_speed;
  const double v_r_max = v_robot.cols() > 0 ? v_robot.colwise().norm().maxCoeff() : 0.0;
  const double sp_undirected = safety::ProtectiveSeparationDistance(s, v_h_max, v_r_max);
  const Eigen::Matrix3Xd& joints = history.back().second;
  SeparationSearch& f = *search;
  for (int h = 0; h < body_.num_spheres(); ++h) {
    const double human_radius = body_.spheres()[static_cast<std::size_t>(h)].radius;
    const Eigen::Vector3d c = body_.SphereCentre(h, joints);
    const Eigen::Vector3d v_c = measured ? body_.SphereCentre(h, v_joints) : Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < robot_spheres.size(); ++k) {
      const Eigen::Index ki = static_cast<Eigen::Index>(k);
      const Eigen::Vector3d delta = data_.p_WS.col(ki) - c;  // human -> robot
      const double centres = delta.norm();
      const double d = centres - robot_spheres[k].radius - human_radius;
      double v_h = v_h_max, v_r = v_r_max, sp = sp_undirected, margin = d - sp_undirected;
      bool retreating = false;
      double slow_scale = safety::SpeedScaleFor(s, d - v_r_max * s.speed_reduction_time, v_h_max, v_r_max);
      double stop_scale = safety::SpeedScaleFor(s, d, v_h_max, v_r_max);
      if (s.directed) {
        // The pair rule the planner predicts (safety::SsmPairRule). Without a
        // measured speed the person comes at the default speed, straight
        // at the robot sphere.
        const Eigen::Vector3d u = centres > 1e-9 ? Eigen::Vector3d(delta / centres) : Eigen::Vector3d::Zero();
        const safety::SsmPair pair = safety::SsmPairRule(s, delta, robot_spheres[k].radius + human_radius,
                                                     measured ? v_c : Eigen::Vector3d(s.default_human_speed * u),
                                                     v_robot.col(ki));
        v_h = pair.v_h;
        v_r = pair.v_r;
        sp = pair.protective_separation;
        retreating = pair.retreating;
        slow_scale = pair.slow_scale;
        stop_scale = pair.stop_scale;
        // A retreat inside S_p is no violation: it binds as a margin of 0
        // (slow down, not stop) unless a pair outside S_p binds tighter.
        margin = retreating ? 0.0 : pair.margin;
      }
      f.slow_scale = std::min(f.slow_scale, slow_scale);
      f.stop_scale = std::min(f.stop_scale, stop_scale);
      if (d < f.best) {
        f.best = d;
        f.closest_k = k;
        f.closest_h = h;
      }
      if (margin < f.best_margin) {
        f.best_margin = margin;
        f.retreating = retreating;
        f.binding_k = k;
        f.binding_h = h;
        r.binding_separation = d;
        r.binding_body_id = f.body;
        r.protective_separation = sp;
        r.human_speed = v_h;
        r.robot_speed = v_r;
      }
    }
  }
}

// Prediction layer: the bound along the executing trajectory at every step
// of the newest prediction not yet past, the union over the persons.
void RiskMonitor::EvaluateBound(int64_t now_ns, RiskReport* out) {
  RiskReport& r = *out;
  // The newest fresh prediction gives the waypoints.
  const cell::TimedPrediction* ref = nullptr;
  for (const auto& [id, e] : predictions_) {
    if (e.value.FreshAt(now_ns, static_cast<int64_t>(params_.stale_after * 1e9)) && (!ref || e.stamp_ns > ref->t0_ns()))
      ref = &e.value;
  }
  const cell::TimedPrediction& m = *ref;
  r.prediction_stamp_ns = m.t0_ns();
  r.time_step = m.time_step();
  collision::RobotSpheresTrajectory traj;
  const int S = static_cast<int>(robot_.spheres.size());
  for (const auto& sp : robot_.spheres) {
    traj.radii.push_back(sp.radius);
    traj.links.push_back(sp.link);
  }
  BoundWaypoints bw;
  bw.ref = ref;
  for (int k = 0; k < m.num_steps(); ++k) {
    if (m.StepTime(k) < now_ns) continue;
    traj.steps.push_back(k);
    bw.times.push_back(m.StepTime(k));
  }
  bw.ref_steps = traj.steps;
  const std::vector<int64_t>& times = bw.times;
  traj.centres.resize(3, static_cast<Eigen::Index>(traj.steps.size()) * S);
  for (std::size_t w = 0; w < traj.steps.size(); ++w) {
    collision::CalcForwardKinematics(robot_, RobotConfigurationAt(times[w]), &data_);
    traj.centres.middleCols(static_cast<Eigen::Index>(w) * S, S) = data_.p_WS;
    r.waypoint_times.push_back((times[w] - now_ns) * 1e-9);
  }
  // Per waypoint: each person's bound, their sum (raw, for the argmax) and
  // the person with the largest share.
  std::vector<std::vector<double>> shares(traj.steps.size());
  std::vector<double> sum(traj.steps.size(), 0.0), share(traj.steps.size(), -1.0);
  std::vector<collision::WaypointBound> top(traj.steps.size());
  std::vector<cell::BodyId> top_body(traj.steps.size(), 0);
  std::vector<const cell::TimedPrediction*> top_prediction(traj.steps.size(), &m);
  ForEachPersonBound(now_ns, bw, &traj, [&](cell::BodyId id, const cell::TimedPrediction& p) {
    for (std::size_t w = 0; w < bounds_.size(); ++w) {
      shares[w].push_back(bounds_[w].bound);
      sum[w] += bounds_[w].bound;
      if (bounds_[w].bound > share[w]) {
        share[w] = bounds_[w].bound;
        top[w] = bounds_[w];
        top_body[w] = id;
        top_prediction[w] = &p;
      }
    }
  });
  for (std::size_t w = 0; w < sum.size(); ++w) {
    const auto& b = top[w];
    r.waypoint_bounds.push_back(cell::UnionBound(shares[w]));
    if (w == 0 || sum[w] > r.max_bound) {
      r.max_bound = r.waypoint_bounds[w];
      r.max_waypoint = static_cast<int>(w);
      r.max_time = r.waypoint_times[w];
      r.max_body_id = top_body[w];
      r.max_robot_link = b.robot_link >= 0 ? robot_.link_names[static_cast<std::size_t>(b.robot_link)] : "";
      r.max_human_segment =
          b.human_segment >= 0 ? body_.params().segments[static_cast<std::size_t>(b.human_segment)].name : "";
      r.max_action = b.action >= 0 ? top_prediction[w]->actions()[static_cast<std::size_t>(b.action)] : "";
    }
  }
  CompareWithStandingStill(now_ns, bw, &traj, &r);
}

// Every fresh person's bound along `t` (its centres set) into bounds_, then
// `use`; each person's prediction taken at its step nearest to each
// waypoint's time (the reference prediction at its own steps).
void RiskMonitor::ForEachPersonBound(int64_t now_ns, const BoundWaypoints& w, collision::RobotSpheresTrajectory* t,
                                     const std::function<void(cell::BodyId, const cell::TimedPrediction&)>& use) {
  for (const auto& [id, e] : predictions_) {
    const cell::TimedPrediction& p = e.value;
    if (!p.FreshAt(now_ns, static_cast<int64_t>(params_.stale_after * 1e9))) continue;
    for (std::size_t i = 0; i < w.times.size(); ++i) {
      const double k = std::round((w.times[i] - p.t0_ns()) * 1e-9 / p.time_step()) - 1;
      t->steps[i] =
          &p == w.ref ? w.ref_steps[i] : static_cast<int>(std::clamp(k, 0.0, static_cast<double>(p.num_steps() - 1)));
    }
    collision::EvaluateTrajectoryBound(p.spheres(), *t, collision::TrajectoryBoundParams{}, &workspace_, &bounds_);
    use(id, p);
  }
}

// Whether the bound retreat applies: on, and the executing trajectory moves
// the robot (by 1 mrad or more at some joint) at one of `times` (ns, in
// order) within the stop horizon; a trajectory that holds it is no retreat.
bool RiskMonitor::MovesWithinStopHorizon(int64_t now_ns, const std::vector<int64_t>& times) const {
  if (params_.bound_retreat_gain <= 0 || trajectory_.empty()) return false;
  double travel = 0;
  for (std::size_t i = 0; i < times.size() && (times[i] - now_ns) * 1e-9 <= params_.stop_horizon; ++i)
    travel = std::max(travel, (RobotConfigurationAt(times[i]) - state_->second).cwiseAbs().maxCoeff());
  return travel >= 1e-3;
}

// The alternative to a stop: the robot held where it stands (DecideVerdict's
// bound retreat), its largest bound within the stop horizon against the
// trajectory's. Not evaluated when the trajectory holds the robot there.
void RiskMonitor::CompareWithStandingStill(int64_t now_ns, const BoundWaypoints& w,
                                           collision::RobotSpheresTrajectory* traj, RiskReport* r) {
  if (!MovesWithinStopHorizon(now_ns, w.times)) return;
  const int S = static_cast<int>(robot_.spheres.size());
  collision::CalcForwardKinematics(robot_, state_->second, &data_);
  for (std::size_t i = 0; i < w.times.size(); ++i) traj->centres.middleCols(static_cast<Eigen::Index>(i) * S, S) = data_.p_WS;
  std::vector<std::vector<double>> hold(w.times.size());
  ForEachPersonBound(now_ns, w, traj, [&](cell::BodyId, const cell::TimedPrediction&) {
    for (std::size_t i = 0; i < bounds_.size(); ++i) hold[i].push_back(bounds_[i].bound);
  });
  r->hold_bound = 0;
  r->horizon_bound = 0;
  for (std::size_t i = 0; i < hold.size() && r->waypoint_times[i] <= params_.stop_horizon; ++i) {
    r->hold_bound = std::max(r->hold_bound, cell::UnionBound(hold[i]));
    r->horizon_bound = std::max(r->horizon_bound, r->waypoint_bounds[i]);
  }
}

// Why an OK verdict is one: what the monitor saw.
const char* RiskMonitor::ClearReason(const Inputs& in, bool seen, bool separation) {
  return !seen         ? "no person seen"
         : !in.person   ? (separation ? "clear (depth points only)" : "no person seen (depth: no points)")
         : in.predicted ? "clear"
         : in.degraded  ? "clear (degraded: no usable prediction; separation at the default human speed)"
                        : "clear (separation only: no current prediction)";
}

namespace {

// s after the evaluation of the first waypoint whose bound reaches
// `threshold`, -1 when none does.
double FirstViolation(const RiskReport& r, double threshold) {
  for (std::size_t w = 0; w < r.waypoint_bounds.size(); ++w)
    if (r.waypoint_bounds[w] >= threshold) return r.waypoint_times[w];
  return -1;
}

}  // namespace

// Verdict: the hard layer first, then the prediction.
void RiskMonitor::DecideVerdict(int64_t now_ns, const Inputs& in, RiskReport* out) const {
  RiskReport& r = *out;
  const double threshold = 1 - params_.delta_cl;
  const double first_violation = FirstViolation(r, threshold);
  const double margin = r.separation_margin.value_or(std::numeric_limits<double>::infinity());
  const std::string separation = r.binding_separation ? Fmt(*r.binding_separation) : std::string("none");
  // With several people the reason names the person (nothing added for one).
  const std::string nearest = r.num_people > 1 ? " (body " + std::to_string(r.binding_body_id) + ")" : "";
  const std::string likeliest = r.num_predicted > 1 ? " (body " + std::to_string(r.max_body_id) + " of " +
                                                          std::to_string(r.num_predicted) + ")"
                                                    : "";
  const bool seen = in.person || in.points;  // fresh points: the depth camera tracks the person
  // Standing still would reach the bound within the stop horizon, and the
  // trajectory lowers it by the gain: it takes the robot out of the way.
  const bool bound_retreat = params_.bound_retreat_gain > 0 && r.hold_bound >= threshold &&
                             r.hold_bound - r.horizon_bound >= params_.bound_retreat_gain;
  // Inside S_p at the trajectory's speed, but not at min_speed_scale of it:
  // the robot is slowed down, not stopped (ISO/TS 15066 speed reduction).
  const safety::SsmParams& s = params_.ssm;
  const bool reducible = s.speed_reduction && r.stop_scale >= s.min_speed_scale;
  if (!seen && params_.person_required) {
    r.verdict = Verdict::kProtectiveStop;
    const int64_t last_seen = std::max(last_skeleton_ns_, points_stamp_ns_);
    r.reason = last_seen == 0 ? "no person tracked yet (no skeleton, no depth points): the person could be anywhere"
                              : "person no longer tracked (no skeleton or depth points for " +
                                    Fmt((now_ns - last_seen) * 1e-9) + " s): the person could be anywhere";
  } else if (seen && margin < 0 && !reducible) {
    r.verdict = Verdict::kProtectiveStop;
    r.reason = "separation " + separation + " m (" + r.binding_robot_link + " / " + r.binding_human_segment +
               (r.num_people > 1 ? " of body " + std::to_string(r.binding_body_id) : "") +
               ") below the protective separation " + Fmt(r.protective_separation) + " m (v_h " + Fmt(r.human_speed) +
               ", v_r " + Fmt(r.robot_speed) + " m/s)";
  } else if (first_violation >= 0 && first_violation <= params_.stop_horizon && bound_retreat) {
    // Stopping would leave the robot where the person is predicted to come:
    // the trajectory that takes it out of their way goes on.
    r.verdict = Verdict::kSlowDown;
    r.retreating = true;
    r.reason = "retreating from the predicted person: collision bound " + Fmt(r.horizon_bound) + " within " +
               Fmt(params_.stop_horizon) + " s along the trajectory against " + Fmt(r.hold_bound) +
               " standing still (" + r.max_robot_link + " / " + r.max_human_segment + ", " + r.max_action + ")" +
               likeliest;
  } else if (first_violation >= 0 && first_violation <= params_.stop_horizon) {
    r.verdict = Verdict::kProtectiveStop;
    r.reason = "collision bound " + Fmt(r.max_bound) + " >= " + Fmt(threshold) + " in " + Fmt(first_violation) +
               " s (" + r.max_robot_link + " / " + r.max_human_segment + ", " + r.max_action +
               (r.num_predicted > 1 ? ", body " + std::to_string(r.max_body_id) + " of " + std::to_string(r.num_predicted)
                                    : "") +
               ")";
  } else if (first_violation >= 0) {
    r.verdict = Verdict::kSlowDown;
    r.reason = "collision bound " + Fmt(r.max_bound) + " >= " + Fmt(threshold) + " in " + Fmt(first_violation) + " s" +
               likeliest;
  } else if (r.max_bound >= params_.slow_down_fraction * threshold) {
    r.verdict = Verdict::kSlowDown;
    r.reason = "collision bound " + Fmt(r.max_bound) + " approaching " + Fmt(threshold) + likeliest;
  } else if (seen && r.retreating) {
    r.verdict = Verdict::kSlowDown;
    r.reason = "retreating: separation " + separation + " m (" + r.binding_robot_link + " / " +
               r.binding_human_segment + ") below the protective separation " + Fmt(r.protective_separation) +
               " m, the robot moving away" + nearest +
               (r.speed_scale < 1.0 ? "; speed reduced to " + Fmt(r.speed_scale) + " of the trajectory's" : "");
  } else if (seen && r.speed_scale < 1.0) {
    r.verdict = Verdict::kSlowDown;
    r.reason = "speed reduced to " + Fmt(r.speed_scale) + " of the trajectory's: separation " + separation + " m (" +
               r.binding_robot_link + " / " + r.binding_human_segment + ") against the protective separation " +
               Fmt(r.protective_separation) + " m at full speed (v_h " + Fmt(r.human_speed) + ", v_r " +
               Fmt(r.robot_speed) + " m/s)" + nearest;
  } else if (seen && margin < params_.slow_down_margin) {
    r.verdict = Verdict::kSlowDown;
    r.reason = "separation " + separation + " m within " + Fmt(params_.slow_down_margin) +
               " m of the protective separation" + nearest;
  } else {
    r.verdict = Verdict::kOk;
    r.reason = ClearReason(in, seen, r.binding_separation.has_value());
  }
  if (r.verdict == Verdict::kProtectiveStop) r.speed_scale = 0.0;
  // Clear, and away from where the person will come: a supervisor that
  // stopped the robot lets it go at once.
  if (r.verdict != Verdict::kProtectiveStop && bound_retreat) r.retreating = true;
}

}  // namespace iplan::collision_risk

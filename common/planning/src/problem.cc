// The problem of one planning attempt (METHOD.md section 5): the request's
// checks, the horizon and initial trajectory, the smoothness metric, the
// prediction step of each waypoint, and exact bounds of fixed waypoints.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "iplan/cell/joint_trajectory.h"
#include "iplan/cell/people.h"
#include "planner_model.h"

namespace iplan::planning::internal {
namespace {

[[noreturn]] void Bad(const std::string& what) { throw std::invalid_argument("Plan: " + what); }

}  // namespace

void PlannerModel::ValidateRequest(const PlanningRequest& req, int num_optimizers, int num_threads) const {
  const int nq = robot.nq;
  if (num_optimizers < 1) Bad("num_optimizers must be >= 1, got " + std::to_string(num_optimizers));
  if (num_threads < 0) Bad("num_threads must be >= 0, got " + std::to_string(num_threads));
  if (req.start_q.size() != nq)
    Bad("start has " + std::to_string(req.start_q.size()) + " joint values, the robot has " + std::to_string(nq));
  if (!req.start_q.allFinite()) Bad("start is not finite: " + VectorText(req.start_q));
  const double tol = 1e-9;
  for (int j = 0; j < nq; ++j)
    if (req.start_q[j] < lower[j] - tol || req.start_q[j] > upper[j] + tol)
      Bad("start joint " + std::to_string(j) + " = " + std::to_string(req.start_q[j]) + " is outside [" +
          std::to_string(lower[j]) + ", " + std::to_string(upper[j]) + "]");
  if (req.start_qdot.size() != 0 && (req.start_qdot.size() != nq || !req.start_qdot.allFinite()))
    Bad("start velocity must have " + std::to_string(nq) + " finite values, got " + VectorText(req.start_qdot));
  if (req.num_frozen < 1) Bad("num_frozen must be >= 1, got " + std::to_string(req.num_frozen));
  if (req.warm_start.size() != 0) {
    if (req.warm_start.rows() != nq || !req.warm_start.allFinite())
      Bad("warm_start must be " + std::to_string(nq) + " x m and finite");
    if ((req.warm_start.col(0) - req.start_q).cwiseAbs().maxCoeff() > 1e-9)
      Bad("warm_start column 0 must equal the start " + VectorText(req.start_q) + ", got " +
          VectorText(req.warm_start.col(0)));
  }
  if (req.num_frozen > 1 && req.warm_start.cols() < req.num_frozen)
    Bad("num_frozen = " + std::to_string(req.num_frozen) + " needs a warm_start with as many columns");
  for (std::size_t p = 0; p < req.people.size(); ++p) {
    const PersonPrediction& person = req.people[p];
    const std::string who = "person " + std::to_string(p) + ": ";
    if (!person.spheres) Bad(who + "prediction is null");
    if (!(person.time_step > 0.0) || !std::isfinite(person.time_step)) Bad(who + "time_step must be > 0 s, got " + std::to_string(person.time_step));
    if (!std::isfinite(person.start)) Bad(who + "start must be finite, got " + std::to_string(person.start));
  }
  if (!req.obstacles.empty()) {
    if (const std::string why = collision::SceneParams{req.obstacles}.Validate(); !why.empty()) Bad("obstacles: " + why);
  }
  if (!(req.ssm_scale >= 0.0 && req.ssm_scale <= 1.0)) Bad("ssm_scale must be in [0, 1], got " + std::to_string(req.ssm_scale));
  if (!(req.time_budget >= 0.0) || !std::isfinite(req.time_budget))
    Bad("time_budget must be finite and >= 0, got " + std::to_string(req.time_budget));
  if (req.goal.kind == Goal::Kind::kJoint) {
    if (req.goal.q.size() != nq)
      Bad("goal has " + std::to_string(req.goal.q.size()) + " joint values, the robot has " + std::to_string(nq));
    if (!req.goal.q.allFinite()) Bad("goal is not finite: " + VectorText(req.goal.q));
    for (int j = 0; j < nq; ++j)
      if (req.goal.q[j] < lower[j] || req.goal.q[j] > upper[j])
        Bad("goal joint " + std::to_string(j) + " = " + std::to_string(req.goal.q[j]) + " is outside [" +
            std::to_string(lower[j]) + ", " + std::to_string(upper[j]) + "]");
  }
}

namespace {

// Intervals of a plan whose first `keep` waypoints are fixed and whose
// motion after them takes `seconds` (a whole number of intervals, up to
// rounding, gets no extra one).
int IntervalsFor(int keep, double seconds, double dt) {
  return (keep - 1) + static_cast<int>(std::ceil(seconds / dt - 1e-9));
}

// The plan's length in intervals, from `n` (the horizon's or a longer warm
// start's): shorter with keep_arrival when the warm start already ends at
// this goal (its arrival kept, the motion's end does not recede a horizon
// with every replan; the arrival is the first column of the run of goal
// columns that ends it, as Planner::ShiftTrajectory pads a shifted plan with
// its last column), else shorter with motion_speed_fraction when the motion
// to this new goal, t_min (s) at the speed limits after `keep` waypoints,
// needs less than the horizon at that fraction of the limits.
int ArrivalLength(const PlannerParams& P, const PlanningRequest& req, const Eigen::VectorXd& q_goal, int keep,
                  double t_min, int n) {
  const int shortest = req.num_frozen + kMinKeptArrivalFree;
  if (P.keep_arrival && req.warm_start.cols() > 1) {
    const auto at_goal = [&](Eigen::Index i) { return (req.warm_start.col(i) - q_goal).cwiseAbs().maxCoeff() < 1e-12; };
    Eigen::Index arrival = req.warm_start.cols() - 1;
    if (at_goal(arrival)) {
      while (arrival > 0 && at_goal(arrival - 1)) --arrival;
      return std::min(n, std::max(static_cast<int>(arrival), shortest));
    }
  }
  if (P.motion_speed_fraction > 0) {
    const double wanted = std::max(P.min_motion_time, kRestToRestPeakFactor * t_min / P.motion_speed_fraction);
    const int fitted = IntervalsFor(keep, wanted, P.dt);
    return std::min(n, std::max(fitted, shortest));
  }
  return n;
}

}  // namespace

Problem PlannerModel::MakeProblem(const PlanningRequest& req, const Eigen::VectorXd& q_goal) const {
  const int nq = robot.nq;
  const PlannerParams& P = params;
  Problem at;
  at.nq = nq;
  at.dt = P.dt;
  for (const auto& o : req.obstacles) at.obstacles.push_back(MakeClearanceObject(o));
  const int horizon_n = std::max(2, static_cast<int>(std::lround(P.horizon / P.dt)));
  at.n = horizon_n;
  // A warm start longer than the horizon (it contains earlier waits) keeps
  // its length, up to twice the horizon, so its remaining motion is not cut.
  if (req.warm_start.cols() - 1 > at.n) at.n = std::min(static_cast<int>(req.warm_start.cols()) - 1, 2 * at.n);
  // t_min: the motion after the frozen prefix at the velocity limits.
  const bool warm = req.warm_start.cols() > 1;
  const int keep = warm ? req.num_frozen : 1;
  const Eigen::VectorXd from = warm ? Eigen::VectorXd(req.warm_start.col(keep - 1)) : req.start_q;
  double t_min = 0.0;
  for (int j = 0; j < nq; ++j) t_min = std::max(t_min, std::abs(q_goal[j] - from[j]) / vmax[j]);
  at.n = ArrivalLength(P, req, q_goal, keep, t_min, at.n);
  // A motion longer than the horizon allows within the velocity limits gets
  // the time it needs after the frozen prefix, up to twice the horizon, and a
  // straight line to the goal as its start; otherwise every attempt would
  // break a velocity limit and the robot would never leave (measured on the
  // Panda: 2.1 rad of joint 1 plans in a 1.5 s horizon, 2.8 rad does not).
  const int need = IntervalsFor(keep, kRestToRestPeakFactor * t_min, P.dt);
  const bool stretched = need > at.n;
  if (stretched) at.n = std::min(need, 2 * horizon_n);
  at.k = req.num_frozen;
  at.ssm_from = at.k;
  at.ssm_margin = req.ssm_scale * P.ssm_margin;
  at.ssm_activation = std::max(req.ssm_scale * P.ssm_activation, std::min(P.ssm_activation, at.ssm_margin + kMinSsmBand));
  if (at.k >= at.n)
    Bad("num_frozen = " + std::to_string(at.k) + " leaves no free waypoint in a horizon of " +
        std::to_string(at.n) + " intervals");
  at.qdot0 = req.start_qdot.size() != 0 ? req.start_qdot : Eigen::VectorXd::Zero(nq);
  at.q_goal = q_goal;
  for (const PersonPrediction& person : req.people) at.people.push_back({person.spheres, person.time_step, person.start, {}});
  at.base.resize(nq, at.n + 1);
  if (warm && stretched) {
    // The frozen prefix, then straight to the goal over the stretched time.
    const int steps = at.n - (keep - 1);
    for (int i = 0; i < keep; ++i) at.base.col(i) = req.warm_start.col(i);
    for (int i = 1; i <= steps; ++i) {
      const double s = static_cast<double>(i) / steps;
      at.base.col(keep - 1 + i) = (1.0 - s) * from + s * q_goal;
    }
  } else if (warm) {
    for (int i = 0; i <= at.n; ++i)
      at.base.col(i) = req.warm_start.col(std::min<Eigen::Index>(i, req.warm_start.cols() - 1));
  } else {
    at.base.col(0) = req.start_q;
    for (int i = 1; i <= at.n; ++i) {
      const double s = static_cast<double>(i) / at.n;
      at.base.col(i) = (1.0 - s) * req.start_q + s * q_goal;
    }
  }
  at.base.col(0) = req.start_q;
  at.base.col(at.n) = q_goal;
  return at;
}

void PlannerModel::PrepareAttempt(Problem* at, bool smooth_base) const {
  at->m = at->n - at->k;
  BuildSmoothness(at);
  SetSteps(at);
  if (smooth_base) {
    // Smoothest trajectory through the frozen prefix and goal: one Newton
    // step on the (quadratic) smoothness from the interpolated base.
    Eigen::MatrixXd A;
    cell::FiniteDifferenceAccelerations(at->base, at->qdot0, at->dt, &A);
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(at->nq, at->m);
    for (int j = at->k; j < at->n; ++j)
      G.col(j - at->k) = (2.0 / at->dt) * (A.col(j - 1) - 2.0 * A.col(j) + A.col(j + 1));
    at->base.middleCols(at->k, at->m) -= G * at->Hinv;
    Project(*at, &at->base);
  }
  FixBounds(at);
}

void PlannerModel::BuildSmoothness(Problem* at) const {
  const int m = at->m;
  // K: rows a_{k-1}..a_n, columns free waypoints k..n-1 (second differences).
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m, m);
  for (int i = at->k - 1; i <= at->n; ++i) {
    // coefficients of q_{i-1}, q_i, q_{i+1} in dt^2 a_i
    const int idx[3] = {i - 1, i, i + 1};
    const double cf[3] = {1.0, -2.0, 1.0};
    for (int a = 0; a < 3; ++a) {
      const int fa = idx[a] - at->k;
      if (fa < 0 || fa >= m) continue;
      for (int b = 0; b < 3; ++b) {
        const int fb = idx[b] - at->k;
        if (fb < 0 || fb >= m) continue;
        H(fa, fb) += cf[a] * cf[b];
      }
    }
  }
  H *= 2.0 / (at->dt * at->dt * at->dt);
  at->Hinv = H.llt().solve(Eigen::MatrixXd::Identity(m, m));
}

void PlannerModel::SetSteps(Problem* at) const {
  for (Problem::Person& person : at->people) {
    person.steps.assign(at->n + 1, 0);
    const int last = person.prediction->num_steps() - 1;
    for (int i = 0; i <= at->n; ++i) {
      const double s = std::round((i * at->dt - person.start) / person.time_step);
      person.steps[i] = static_cast<int>(std::clamp(s, 0.0, static_cast<double>(last)));
    }
  }
}

void PlannerModel::PrepareWorkspace(const Problem& at, Workspace* ws) const {
  const int W = at.n + 1;
  while (static_cast<int>(ws->data.size()) < W) ws->data.emplace_back(robot);
  if (at.people.empty()) return;
  // Only the free waypoints k..n-1 are evaluated: the others never change
  // (FixBounds).
  ws->sub.centres.resize(3, static_cast<Eigen::Index>(at.n - at.k) * radii.size());
  ws->sub.steps.reserve(at.n - at.k);
  ws->sub.radii.reserve(radii.size());
  ws->sub.links.reserve(radii.size());
  ws->sub_spheres.reserve(radii.size());
  ws->active.reserve(at.n - at.k);
  ws->active_bounds.reserve(at.n - at.k);
  int max_h = 0;
  for (const Problem::Person& person : at.people) max_h = std::max(max_h, person.prediction->num_spheres());
  if (!ws->bound_ws || static_cast<int>(ws->bound_ws->log_volume.size()) < static_cast<int>(radii.size()) * max_h)
    ws->bound_ws = std::make_unique<collision::TrajectoryBoundWorkspace>(static_cast<int>(radii.size()), max_h);
  ws->group_log_volume.resize(at.people.size());
  for (std::size_t p = 0; p < at.people.size(); ++p) {
    const collision::HumanPrediction& hp = *at.people[p].prediction;
    const int H = hp.num_spheres();
    std::vector<double>& glv = ws->group_log_volume[p];
    glv.resize(link_groups.size() * H);
    for (std::size_t g = 0; g < link_groups.size(); ++g) {
      double r = 0.0;
      for (int sp : link_groups[g]) r = std::max(r, radii[sp]);
      for (int l = 0; l < H; ++l) glv[g * H + l] = std::log(collision::BallVolume(r + hp.radius(l)));
    }
  }
}

void PlannerModel::ExactBounds(const Problem& at, const Eigen::MatrixXd& Q, int from, int to,
                               std::vector<double>* out) const {
  const int S = static_cast<int>(radii.size());
  collision::RobotSpheresTrajectory rs;
  rs.radii = radii;
  rs.links = links;
  rs.centres.resize(3, static_cast<Eigen::Index>(to - from + 1) * S);
  collision::RobotData d(robot);
  for (int i = from; i <= to; ++i) {
    collision::CalcForwardKinematics(robot, Q.col(i), &d);
    rs.centres.middleCols(static_cast<Eigen::Index>(i - from) * S, S) = d.p_WS;
  }
  // Per person, then the union over persons.
  std::vector<std::vector<double>> shares(static_cast<std::size_t>(to - from + 1));
  std::vector<collision::WaypointBound> wb;
  for (const Problem::Person& person : at.people) {
    rs.steps.assign(person.steps.begin() + from, person.steps.begin() + to + 1);
    collision::TrajectoryBoundWorkspace bw(S, person.prediction->num_spheres());
    collision::EvaluateTrajectoryBound(*person.prediction, rs, collision::TrajectoryBoundParams{}, &bw, &wb);
    for (int i = from; i <= to; ++i) shares[static_cast<std::size_t>(i - from)].push_back(wb[i - from].bound);
  }
  for (int i = from; i <= to; ++i) (*out)[i] = cell::UnionBound(shares[static_cast<std::size_t>(i - from)]);
}

void PlannerModel::FixBounds(Problem* at) const {
  at->fixed_bounds.assign(at->n + 1, 0.0);
  if (at->people.empty()) return;
  ExactBounds(*at, at->base, 0, at->k - 1, &at->fixed_bounds);
  ExactBounds(*at, at->base, at->n, at->n, &at->fixed_bounds);
}

double PlannerModel::HumanSeparation(const Problem& at, const Eigen::MatrixXd& Q, int from, int to) const {
  double best = std::numeric_limits<double>::infinity();
  collision::RobotData d(robot);
  for (int i = from; i <= to; ++i) {
    collision::CalcForwardKinematics(robot, Q.col(i), &d);
    for (const Problem::Person& person : at.people) {  // the nearest person's
      const collision::HumanPrediction& hp = *person.prediction;
      for (int a = 0; a < hp.num_actions(); ++a) {
        if (hp.action_probability(a) < kSeparationMinProbability) continue;
        for (int l = 0; l < hp.num_spheres(); ++l) {
          const Eigen::Vector3d& mu = hp.sphere(a, person.steps[i], l).mean;
          for (int s = 0; s < static_cast<int>(radii.size()); ++s)
            best = std::min(best, (d.p_WS.col(s) - mu).norm() - radii[s] - hp.radius(l));
        }
      }
    }
  }
  return best;
}

}  // namespace iplan::planning::internal

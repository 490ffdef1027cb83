#include "services/trajopt/core/escape.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "iplan/cell/people.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/trajectory_bound.h"

namespace iplan::trajopt {

double HoldBound(const planning::Planner& planner, const planning::PlanningRequest& req, const Eigen::VectorXd& q,
                 double horizon) {
  const collision::RobotModel& robot = planner.robot();
  const double dt = planner.params().dt;
  const int n = static_cast<int>(std::floor(horizon / dt + 1e-9));
  if (req.people.empty() || n < 1) return 0.0;
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, q, &d);
  const int S = static_cast<int>(robot.spheres.size());
  collision::RobotSpheresTrajectory traj;
  for (const auto& sp : robot.spheres) {
    traj.radii.push_back(sp.radius);
    traj.links.push_back(sp.link);
  }
  traj.centres.resize(3, static_cast<Eigen::Index>(n) * S);
  for (int w = 0; w < n; ++w) traj.centres.middleCols(static_cast<Eigen::Index>(w) * S, S) = d.p_WS;
  traj.steps.resize(static_cast<std::size_t>(n));
  std::vector<std::vector<double>> shares(static_cast<std::size_t>(n));
  std::vector<collision::WaypointBound> bounds;
  for (const planning::PersonPrediction& person : req.people) {
    collision::TrajectoryBoundWorkspace workspace(S, person.spheres->num_spheres());
    const int last = person.spheres->num_steps() - 1;
    for (int w = 0; w < n; ++w) {  // waypoint w + 1 at (w + 1) dt, its nearest step (planner.h)
      const double s = std::round(((w + 1) * dt - person.start) / person.time_step);
      traj.steps[static_cast<std::size_t>(w)] = static_cast<int>(std::clamp(s, 0.0, static_cast<double>(last)));
    }
    collision::EvaluateTrajectoryBound(*person.spheres, traj, collision::TrajectoryBoundParams{}, &workspace, &bounds);
    for (int w = 0; w < n; ++w) shares[static_cast<std::size_t>(w)].push_back(bounds[static_cast<std::size_t>(w)].bound);
  }
  double worst = 0.0;
  for (const auto& s : shares) worst = std::max(worst, cell::UnionBound(s));
  return worst;
}

double HorizonBound(const std::vector<double>& bounds, double dt, double horizon) {
  double worst = 0.0;
  for (std::size_t i = 1; i < bounds.size() && i * dt <= horizon + 1e-9; ++i) worst = std::max(worst, bounds[i]);
  return worst;
}

std::optional<AwayFromPerson> FindAwayFromPerson(const planning::Planner& planner, const planning::PlanningRequest& req,
                                                 const Eigen::VectorXd& q, bool last_step_only) {
  const collision::RobotModel& robot = planner.robot();
  const int ee = robot.FindLink(planner.params().end_effector_link);
  if (ee < 0 || req.people.empty()) return std::nullopt;
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, q, &d);
  const auto& offset = planner.params().end_effector_offset;
  AwayFromPerson out;
  out.p_WE = d.X_WL[static_cast<std::size_t>(ee)] * Eigen::Vector3d(offset[0], offset[1], offset[2]);
  out.R_WE = Eigen::Quaterniond(d.X_WL[static_cast<std::size_t>(ee)].rotation());
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d nearest = out.p_WE;
  for (const planning::PersonPrediction& person : req.people) {
    const collision::HumanPrediction& hp = *person.spheres;
    for (int a = 0; a < hp.num_actions(); ++a) {
      for (int k = last_step_only ? hp.num_steps() - 1 : 0; k < hp.num_steps(); ++k) {
        for (int l = 0; l < hp.num_spheres(); ++l) {
          const Eigen::Vector3d& mu = hp.sphere(a, k, l).mean;
          if ((mu - out.p_WE).norm() < best) {
            best = (mu - out.p_WE).norm();
            nearest = mu;
          }
        }
      }
    }
  }
  out.away = out.p_WE - nearest;
  out.away.z() = 0;
  return out;
}

std::vector<Eigen::VectorXd> AsideGoals(const planning::Planner& planner, const planning::PlanningRequest& req,
                                        const Eigen::VectorXd& q, double distance) {
  const collision::RobotModel& robot = planner.robot();
  std::vector<Eigen::VectorXd> goals;
  if (req.people.empty()) return goals;
  if (const std::optional<AwayFromPerson> e = FindAwayFromPerson(planner, req, q, false)) {
    const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d back(-e->p_WE.x(), -e->p_WE.y(), 0.0);  // towards the base (W = base frame)
    std::vector<Eigen::Vector3d> directions = {up, back};
    if (e->away.norm() > 1e-6) directions.insert(directions.begin(), {e->away.normalized(), e->away.normalized() + up});
    std::uint64_t seed = 1;
    for (const Eigen::Vector3d& direction : directions) {
      if (direction.norm() < 1e-6) continue;
      const planning::IkResult ik = planner.SolveIk(e->p_WE + distance * direction.normalized(), e->R_WE, q, seed++);
      if (ik.success) goals.push_back(ik.q);
    }
  }
  // In joint space (any arm, no IK): each of the first four joints turned
  // by +-0.4 rad, within the limits.
  constexpr double kTurn = 0.4;  // rad
  const Eigen::VectorXd lower = robot.LowerLimits(), upper = robot.UpperLimits();
  for (int j = 0; j < std::min<int>(4, static_cast<int>(q.size())); ++j) {
    for (double sign : {-1.0, 1.0}) {
      Eigen::VectorXd g = q;
      g[j] = std::clamp(q[j] + sign * kTurn, lower[j] + 0.05, upper[j] - 0.05);
      if (std::abs(g[j] - q[j]) > 0.1) goals.push_back(g);
    }
  }
  return goals;
}

std::optional<planning::PlanningResult> FindEscape(const planning::Planner& planner, planning::PlanningRequest req,
                                                   const planning::PlanningResult& failed, const Eigen::VectorXd& q,
                                                   double hold_bound, const EscapeParams& params,
                                                   double time_budget) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point t0 = Clock::now();
  const auto left = [&] { return time_budget - std::chrono::duration<double>(Clock::now() - t0).count(); };
  if (params.horizon <= 0 || params.gain <= 0) return std::nullopt;
  const double dt = planner.params().dt;
  std::optional<planning::PlanningResult> best;
  double best_bound = hold_bound - params.gain;
  const auto consider = [&](const planning::PlanningResult& res) {
    if (res.positions.cols() < 2 || res.bounds.empty()) return;
    if (res.status == planning::PlanStatus::kInfeasible || res.min_clearance < planner.params().min_clearance) return;
    if (!planning::CheckLimits(planner.robot(), res.positions, dt, req.start_qdot, 1e-6).empty()) return;
    const double bound = HorizonBound(res.bounds, dt, params.horizon);
    if (bound <= best_bound) {
      best_bound = bound;
      best = res;
    }
  };
  consider(failed);
  req.max_waits = 0;  // a wait is what standing still already is
  // Each aside goal starts from the frozen prefix and a straight line to it
  // over the horizon (a warm start that ends elsewhere would leave the
  // optimiser a jump to the goal at its last waypoint).
  const Eigen::MatrixXd prefix = req.warm_start;
  const int keep = prefix.cols() > 1 ? std::max(1, req.num_frozen) : 1;
  const int n = std::max(keep + 1, static_cast<int>(std::lround(planner.params().horizon / dt)));
  const Eigen::VectorXd from = keep > 1 ? Eigen::VectorXd(prefix.col(keep - 1)) : req.start_q;
  const std::vector<Eigen::VectorXd> goals = AsideGoals(planner, req, q, params.distance);
  for (std::size_t g = 0; g < goals.size(); ++g) {
    const Eigen::VectorXd& goal = goals[g];
    if (time_budget > 0) {
      if (left() <= 0) break;
      req.time_budget = left() / static_cast<double>(goals.size() - g);
    }
    req.goal = planning::Goal::Joint(goal);
    req.warm_start.resize(from.size(), n + 1);
    for (int i = 0; i < keep; ++i) req.warm_start.col(i) = keep > 1 ? Eigen::VectorXd(prefix.col(i)) : req.start_q;
    for (int i = keep; i <= n; ++i) {
      const double s = static_cast<double>(i - keep + 1) / (n - keep + 1);
      req.warm_start.col(i) = (1.0 - s) * from + s * goal;
    }
    try {
      consider(planner.Plan(req));
    } catch (const std::exception&) {
      // An aside goal outside the limits or the workspace is not an escape.
    }
  }
  return best;
}

}  // namespace iplan::trajopt

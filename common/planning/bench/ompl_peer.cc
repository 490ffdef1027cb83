#include "ompl_peer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

namespace iplan::planning::bench {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using Clock = std::chrono::steady_clock;

// Position s(t) in [0, 1] of a rest-to-rest trapezoidal profile over unit
// distance with peak speed v and acceleration a (1/s, 1/s^2), and its length.
struct Trapezoid {
  double v, a, t_acc, t_total;
  Trapezoid(double v_max, double a_max) : v(v_max), a(a_max) {
    t_acc = v / a;
    if (a * t_acc * t_acc >= 1.0) {  // triangle: never reaches v
      t_acc = std::sqrt(1.0 / a);
      v = a * t_acc;
      t_total = 2.0 * t_acc;
    } else {
      t_total = 2.0 * t_acc + (1.0 - a * t_acc * t_acc) / v;
    }
  }
  double At(double t) const {
    if (t <= 0.0) return 0.0;
    if (t >= t_total) return 1.0;
    if (t < t_acc) return 0.5 * a * t * t;
    if (t > t_total - t_acc) {
      const double r = t_total - t;
      return 1.0 - 0.5 * a * r * r;
    }
    return 0.5 * a * t_acc * t_acc + v * (t - t_acc);
  }
};

// The path's waypoints timed segment by segment (rest to rest), sampled
// every dt from 0 to the end, the last sample at the goal.
Eigen::MatrixXd TimeParameterise(const std::vector<Eigen::VectorXd>& path, const Eigen::VectorXd& vmax,
                                 const Eigen::VectorXd& amax, double dt) {
  struct Segment {
    double start;  // s
    Trapezoid profile;
    std::size_t from;
  };
  std::vector<Segment> segments;
  double end = 0.0;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::VectorXd d = path[i + 1] - path[i];
    double v_s = std::numeric_limits<double>::infinity(), a_s = v_s;
    for (Eigen::Index j = 0; j < d.size(); ++j) {
      if (std::abs(d[j]) < 1e-12) continue;
      v_s = std::min(v_s, vmax[j] / std::abs(d[j]));
      a_s = std::min(a_s, amax[j] / std::abs(d[j]));
    }
    if (!std::isfinite(v_s)) continue;  // a repeated waypoint
    segments.push_back({end, Trapezoid(v_s, a_s), i});
    end += segments.back().profile.t_total;
  }
  const Eigen::Index n = static_cast<Eigen::Index>(std::ceil(end / dt - 1e-9));
  Eigen::MatrixXd Q(path.front().size(), n + 1);
  std::size_t k = 0;
  for (Eigen::Index i = 0; i <= n; ++i) {
    const double t = std::min(i * dt, end);
    while (k + 1 < segments.size() && t >= segments[k + 1].start) ++k;
    if (segments.empty()) {
      Q.col(i) = path.front();
      continue;
    }
    const Segment& sg = segments[k];
    Q.col(i) = path[sg.from] + sg.profile.At(t - sg.start) * (path[sg.from + 1] - path[sg.from]);
  }
  Q.col(n) = path.back();
  return Q;
}

}  // namespace

PeerResult PlanWithRrtConnect(const Planner& planner, const Eigen::VectorXd& start, const Eigen::VectorXd& goal,
                              double time_limit, std::uint64_t seed) {
  static const bool seeded = [seed] {
    ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
    ompl::RNG::setSeed(seed);
    return true;
  }();
  (void)seeded;
  const collision::RobotModel& robot = planner.robot();
  const PlannerParams& params = planner.params();
  const int nq = robot.nq;
  const Eigen::VectorXd lo = robot.LowerLimits(), hi = robot.UpperLimits();
  auto space = std::make_shared<ob::RealVectorStateSpace>(nq);
  ob::RealVectorBounds bounds(nq);
  for (int j = 0; j < nq; ++j) {
    bounds.setLow(j, lo[j] + params.position_margin);
    bounds.setHigh(j, hi[j] - params.position_margin);
  }
  space->setBounds(bounds);
  og::SimpleSetup ss(space);
  ss.setStateValidityChecker([&](const ob::State* s) {
    const double* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
    return planner.CalcClearance(Eigen::Map<const Eigen::VectorXd>(v, nq)) >= params.min_clearance;
  });
  // Motions checked every ~0.01 rad (the optimiser checks each 0.1 s
  // interval at collision_check_substeps points).
  ss.getSpaceInformation()->setStateValidityCheckingResolution(0.01 / space->getMaximumExtent());
  ob::ScopedState<> s(space), g(space);
  for (int j = 0; j < nq; ++j) {
    s[j] = start[j];
    g[j] = goal[j];
  }
  ss.setStartAndGoalStates(s, g);
  ss.setPlanner(std::make_shared<og::RRTConnect>(ss.getSpaceInformation()));
  PeerResult r;
  const auto t0 = Clock::now();
  const ob::PlannerStatus status = ss.solve(time_limit);
  r.time_to_solution = std::chrono::duration<double>(Clock::now() - t0).count();
  r.solved = status == ob::PlannerStatus::EXACT_SOLUTION;
  if (!r.solved) {
    r.planning_time = r.time_to_solution;
    return r;
  }
  og::PathGeometric& path = ss.getSolutionPath();
  og::PathSimplifier(ss.getSpaceInformation()).simplifyMax(path);
  r.planning_time = std::chrono::duration<double>(Clock::now() - t0).count();
  std::vector<Eigen::VectorXd> waypoints;
  for (const ob::State* st : path.getStates()) {
    const double* v = st->as<ob::RealVectorStateSpace::StateType>()->values;
    waypoints.emplace_back(Eigen::Map<const Eigen::VectorXd>(v, nq));
  }
  Eigen::VectorXd vmax(nq), amax(nq);
  for (int j = 0; j < nq; ++j) {
    const auto& L = robot.joints[static_cast<std::size_t>(robot.q_joints[static_cast<std::size_t>(j)])].limits;
    vmax[j] = params.limit_scale * L.velocity;
    amax[j] = params.limit_scale * L.acceleration;
  }
  r.positions = TimeParameterise(waypoints, vmax, amax, params.dt);
  return r;
}

}  // namespace iplan::planning::bench

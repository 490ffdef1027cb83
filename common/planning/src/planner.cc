// Planner: the public face of the ITOMP-style optimiser. Plan() orchestrates
// the pieces of planner_model.h (METHOD.md section 5).
#include "iplan/planning/planner.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

#include "iplan/cell/joint_trajectory.h"
#include "planner_model.h"

namespace iplan::planning {

using internal::Candidate;
using internal::Clock;
using internal::PlannerModel;
using internal::Problem;
using internal::Seconds;

Goal Goal::Joint(Eigen::VectorXd q) {
  Goal g;
  g.kind = Kind::kJoint;
  g.q = std::move(q);
  return g;
}

Goal Goal::Pose(const Eigen::Vector3d& p_WE, const Eigen::Quaterniond& R_WE) {
  Goal g;
  g.kind = Kind::kPose;
  g.p_WE = p_WE;
  g.R_WE = R_WE;
  return g;
}

const char* ToString(PlanStatus status) {
  switch (status) {
    case PlanStatus::kSuccess: return "success";
    case PlanStatus::kSuccessAfterWait: return "success_after_wait";
    case PlanStatus::kNoSafeTrajectory: return "no_safe_trajectory";
    case PlanStatus::kInfeasible: return "infeasible";
    case PlanStatus::kIkFailed: return "ik_failed";
    case PlanStatus::kGoalInCollision: return "goal_in_collision";
  }
  return "unknown";
}

std::string CheckLimits(const collision::RobotModel& robot, const Eigen::MatrixXd& Q, double dt,
                        const Eigen::VectorXd& qdot0, double tol) {
  const int nq = robot.nq;
  if (Q.rows() != nq)
    return "trajectory has " + std::to_string(Q.rows()) + " rows, robot nq " + std::to_string(nq);
  const int W = static_cast<int>(Q.cols());
  Eigen::MatrixXd V, A;
  cell::FiniteDifferenceVelocities(Q, dt, &V);
  cell::FiniteDifferenceAccelerations(Q, qdot0.size() == nq ? qdot0 : Eigen::VectorXd::Zero(nq), dt, &A);
  std::ostringstream s;
  s.precision(10);
  for (int j = 0; j < nq; ++j) {
    const collision::JointLimits& L = robot.joints[robot.q_joints[j]].limits;
    for (int i = 0; i < W; ++i) {
      const double q = Q(j, i);
      if (!std::isfinite(q) || q < L.lower - tol || q > L.upper + tol) {
        s << "position of joint " << j << " at waypoint " << i << " is " << q << ", limits [" << L.lower << ", "
          << L.upper << "]";
        return s.str();
      }
      if (i + 1 < W && std::abs(V(j, i)) > L.velocity * (1.0 + tol)) {
        s << "velocity of joint " << j << " at waypoint " << i << " is " << V(j, i) << ", limit " << L.velocity;
        return s.str();
      }
      if (std::abs(A(j, i)) > L.acceleration * (1.0 + tol)) {
        s << "acceleration of joint " << j << " at waypoint " << i << " is " << A(j, i) << ", limit "
          << L.acceleration;
        return s.str();
      }
    }
  }
  return "";
}

struct Planner::Impl : PlannerModel {
  using PlannerModel::PlannerModel;
};

Planner::Planner(collision::RobotModel robot, collision::SceneParams scene, PlannerParams params)
    : impl_(std::make_unique<Impl>(std::move(robot), std::move(scene), std::move(params))) {}

Planner::~Planner() = default;

const collision::RobotModel& Planner::robot() const { return impl_->robot; }
const PlannerParams& Planner::params() const { return impl_->params; }

namespace {

IkOptions IkOptionsOf(const PlannerParams& p) {
  IkOptions opt;
  opt.max_iterations = p.ik_max_iterations;
  opt.damping = p.ik_damping;
  opt.position_tolerance = p.ik_position_tolerance;
  opt.orientation_tolerance = p.ik_orientation_tolerance;
  opt.restarts = p.ik_restarts;
  opt.position_margin = p.position_margin;
  return opt;
}

}  // namespace

IkResult Planner::SolveIk(const Eigen::Vector3d& p_WE, const Eigen::Quaterniond& R_WE,
                          const Eigen::VectorXd& q_seed, std::uint64_t seed) const {
  const internal::PlannerModel& I = *impl_;
  if (!p_WE.allFinite() || !R_WE.coeffs().allFinite() || std::abs(R_WE.norm() - 1.0) > 1e-3)
    throw std::invalid_argument("SolveIk: goal pose must be finite with a unit quaternion, got p " +
                                internal::VectorText(p_WE) + ", q (x,y,z,w) " + internal::VectorText(R_WE.coeffs()));
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R_WE.normalized().toRotationMatrix();
  X.translation() = p_WE;
  std::mt19937_64 rng(internal::SplitMix(seed));
  return planning::SolveIk(*I.chains, I.ee_link, I.ee_offset, X, q_seed, IkOptionsOf(I.params), &rng);
}

IkResult Planner::SolveIkForToolAxis(const Eigen::Vector3d& p_WE, const Eigen::Vector3d& z_W,
                                     const Eigen::VectorXd& q_seed, std::uint64_t seed, int restarts) const {
  const internal::PlannerModel& I = *impl_;
  if (!p_WE.allFinite() || !z_W.allFinite() || std::abs(z_W.norm() - 1.0) > 1e-3)
    throw std::invalid_argument("SolveIkForToolAxis: need a finite position and a unit axis, got p " +
                                internal::VectorText(p_WE) + ", z " + internal::VectorText(z_W));
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), z_W).toRotationMatrix();
  X.translation() = p_WE;
  IkOptions opt = IkOptionsOf(I.params);
  opt.align_axis_L = Eigen::Vector3d::UnitZ();
  if (restarts >= 0) opt.restarts = restarts;
  std::mt19937_64 rng(internal::SplitMix(seed));
  return planning::SolveIk(*I.chains, I.ee_link, I.ee_offset, X, q_seed, opt, &rng);
}

double Planner::CalcClearance(const Eigen::VectorXd& q) const { return CalcClearance(q, {}); }

double Planner::CalcClearance(const Eigen::VectorXd& q, const std::vector<collision::SceneObject>& obstacles) const {
  if (q.size() != impl_->robot.nq || !q.allFinite())
    throw std::invalid_argument("CalcClearance: q must have " + std::to_string(impl_->robot.nq) +
                                " finite values, got " + internal::VectorText(q));
  collision::RobotData d(impl_->robot);
  collision::CalcForwardKinematics(impl_->robot, q, &d);
  std::vector<internal::ClearanceObject> extra;
  for (const auto& o : obstacles) extra.push_back(internal::MakeClearanceObject(o));
  return impl_->Clearance(d, &extra);
}

std::vector<int> Planner::CheckedSpheres(int object) const {
  std::vector<int> out;
  for (std::size_t s = 0; s < impl_->radii.size(); ++s)
    if (impl_->checked[s].at(object)) out.push_back(static_cast<int>(s));
  return out;
}

Eigen::MatrixXd Planner::ShiftTrajectory(const Eigen::MatrixXd& previous, double dt,
                                         double elapsed) {
  if (previous.cols() < 1) throw std::invalid_argument("ShiftTrajectory: empty trajectory");
  if (!(dt > 0.0) || !(elapsed >= 0.0) || !std::isfinite(elapsed))
    throw std::invalid_argument("ShiftTrajectory: need dt > 0 and finite elapsed >= 0, got dt " +
                                std::to_string(dt) + ", elapsed " + std::to_string(elapsed));
  const Eigen::Index shift = static_cast<Eigen::Index>(std::llround(elapsed / dt));
  Eigen::MatrixXd out(previous.rows(), previous.cols());
  for (Eigen::Index i = 0; i < previous.cols(); ++i)
    out.col(i) = previous.col(std::min(i + shift, previous.cols() - 1));
  return out;
}

PlanningResult Planner::Plan(const PlanningRequest& request) const {
  return Plan(request, impl_->params.num_optimizers, impl_->params.num_threads, impl_->params.seed);
}

namespace {

// The result's trajectory and its figures from a candidate.
void Fill(const Candidate& c, int num_frozen, PlanningResult* result) {
  result->positions = c.Q;
  result->cost = c.cost;
  result->max_bound = c.max_bound;
  result->bounds = c.bounds;
  result->min_clearance = c.min_clearance;
  result->ssm_margin = c.ssm.min_margin;
  result->num_frozen = num_frozen;
}

// The best failure: the selection's reference, else the lowest-cost candidate.
int PickFailure(const std::vector<Candidate>& cands, int reference) {
  int pick = reference;
  if (pick < 0)
    for (int o = 0; o < static_cast<int>(cands.size()); ++o)
      if (pick < 0 || cands[o].cost < cands[pick].cost) pick = o;
  return pick;
}

// Status and reason of a plan no attempt made feasible and safe.
void DescribeFailure(const PlannerModel& M, const Problem& at, const Candidate& best, bool any_static,
                     PlanningResult* result) {
  Fill(best, at.k, result);
  std::ostringstream s;
  if (any_static && !at.people.empty()) {
    result->status = PlanStatus::kNoSafeTrajectory;
    if (best.first_unsafe >= 0 || best.ssm.ok()) {
      s << "no trajectory kept the bound below " << M.Threshold() << " after " << result->num_waits
        << " waits; best max bound " << best.max_bound;
    } else {
      const safety::SsmPair& v = best.ssm.violation;
      s << "the separation monitor would stop every trajectory after " << result->num_waits
        << " waits; best: separation " << v.separation << " m below S_p " << v.protective_separation << " + "
        << at.ssm_margin << " m (v_h " << v.v_h << ", v_r " << v.v_r << " m/s) at waypoint "
        << best.ssm.first_violation;
    }
  } else {
    result->status = PlanStatus::kInfeasible;
    const std::string lim = CheckLimits(M.robot, best.Q, M.params.dt, at.qdot0);
    s << "no trajectory satisfied the limits and the static clearance; best: " << (lim.empty() ? "limits ok" : lim)
      << ", clearance " << best.min_clearance << " m";
  }
  result->reason = s.str();
}

// The optimisers' bounds below the dynamic cost's activation are upper
// bounds (see AddDynamicCost); exact values for the returned trajectory.
void ReportExactBounds(const PlannerModel& M, const Problem& at, PlanningResult* result) {
  if (at.people.empty() || result->positions.cols() != at.n + 1) return;
  M.ExactBounds(at, result->positions, 0, at.n, &result->bounds);
  result->max_bound = 0.0;
  for (int i = at.k; i <= at.n; ++i) result->max_bound = std::max(result->max_bound, result->bounds[i]);
  result->human_separation = M.HumanSeparation(at, result->positions, at.k, at.n - 1);
}

}  // namespace

// The goal configuration: the joint goal, or IK of the pose goal seeded at
// the end of the warm start. Sets the IK failure status and returns false
// when there is none.
bool Planner::ResolveGoal(const PlanningRequest& req, std::uint64_t seed, Eigen::VectorXd* q_goal,
                          PlanningResult* result) const {
  if (req.goal.kind == Goal::Kind::kJoint) {
    *q_goal = req.goal.q;
    return true;
  }
  const Eigen::VectorXd ik_seed = req.warm_start.cols() > 1
                                      ? Eigen::VectorXd(req.warm_start.col(req.warm_start.cols() - 1))
                                      : req.start_q;
  const IkResult ik = SolveIk(req.goal.p_WE, req.goal.R_WE, ik_seed, seed);
  if (!ik.success) {
    result->status = PlanStatus::kIkFailed;
    std::ostringstream s;
    s << "no IK solution for the goal pose: best position error " << ik.position_error
      << " m, orientation error " << ik.orientation_error << " rad";
    result->reason = s.str();
    return false;
  }
  *q_goal = ik.q;
  return true;
}

PlanningResult Planner::Plan(const PlanningRequest& req, int num_optimizers, int num_threads,
                             std::uint64_t seed) const {
  const auto t0 = Clock::now();
  const PlannerModel& M = *impl_;
  const PlannerParams& P = M.params;
  M.ValidateRequest(req, num_optimizers, num_threads);
  PlanningResult result;
  result.dt = P.dt;
  Eigen::VectorXd q_goal;
  if (!ResolveGoal(req, seed, &q_goal, &result)) {
    result.planning_time = Seconds(t0, Clock::now());
    return result;
  }
  result.goal_q = q_goal;
  if (const double c = CalcClearance(q_goal, req.obstacles); c < P.min_clearance) {
    result.status = PlanStatus::kGoalInCollision;
    result.reason = "goal configuration has clearance " + std::to_string(c) + " m < " +
                    std::to_string(P.min_clearance) + " m";
    result.planning_time = Seconds(t0, Clock::now());
    return result;
  }
  Problem at = M.MakeProblem(req, q_goal);
  // The optimisers stop early enough that the checks after them fit in the budget.
  if (req.time_budget > 0.0)
    at.deadline = t0 + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(req.time_budget * (1.0 - P.budget_reserve)));
  // The initial warm start keeps its shape; other first attempts are smoothed.
  const bool warm = req.warm_start.cols() > 1;
  const int wait_steps = std::max(1, static_cast<int>(std::round(P.wait_duration / P.dt)));
  Candidate best_fail;
  bool have_fail = false, any_static = false;
  for (int attempt = 0;; ++attempt) {
    M.PrepareAttempt(&at, !warm && attempt == 0);
    const std::vector<Candidate> cands = M.RunOptimizers(at, num_optimizers, num_threads, seed, t0);
    result.budget_exhausted = result.budget_exhausted || at.OutOfTime();
    const internal::Selection sel = PlannerModel::Select(cands);
    any_static = any_static || sel.reference >= 0;
    if (sel.winner >= 0) {
      Fill(cands[sel.winner], at.k, &result);
      result.status = result.num_waits > 0 ? PlanStatus::kSuccessAfterWait : PlanStatus::kSuccess;
      result.winning_optimizer = sel.winner;
      result.num_feasible = sel.num_feasible;
      result.time_to_first_feasible = sel.first_feasible_time;
      break;
    }
    const int pick = PickFailure(cands, sel.reference);
    best_fail = cands[pick];
    have_fail = true;
    result.winning_optimizer = pick;
    // Waiting helps only against the person, and takes another attempt.
    const int max_waits = req.max_waits >= 0 ? req.max_waits : P.max_waits;
    if (at.people.empty() || result.num_waits >= max_waits || at.OutOfTime()) break;
    M.InsertWait(&at, sel.reference >= 0 ? &cands[sel.reference] : nullptr, wait_steps);
    ++result.num_waits;
    result.delay += wait_steps * P.dt;
  }
  if (!result.success() && have_fail) DescribeFailure(M, at, best_fail, any_static, &result);
  ReportExactBounds(M, at, &result);
  result.planning_time = Seconds(t0, Clock::now());
  return result;
}

}  // namespace iplan::planning

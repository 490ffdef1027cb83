#include "services/supervisor/core/task_goals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <utility>
#include <sstream>
#include <stdexcept>

#include "iplan/collision/robot_model.h"
#include "iplan/collision/self_collision.h"

namespace iplan::supervisor {
namespace {

constexpr int kAttempts = 16;  // IK starts per place

Eigen::Vector3d Vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

std::string Text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s.precision(3);
  s << std::fixed << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

class Resolver {
 public:
  Resolver(const planning::Planner& planner, const GoalOptions& options)
      : planner_(planner), robot_(planner.robot()), data_(robot_), options_(options) {
    ee_link_ = robot_.FindLink(planner.params().end_effector_link);
    const auto& o = planner.params().end_effector_offset;
    ee_offset_ = Eigen::Vector3d(o[0], o[1], o[2]);
    seed_ = 0.5 * (robot_.LowerLimits() + robot_.UpperLimits());
    for (Eigen::Index i = 0; i < seed_.size(); ++i)
      if (!std::isfinite(seed_[i])) seed_[i] = 0.0;
  }

  // The places given as poses, for choosing the rest place.
  void SetPlaces(std::vector<ToolPose> places) { places_ = std::move(places); }

  void SetSeed(const std::vector<double>& q) {
    seed_ = Eigen::Map<const Eigen::VectorXd>(q.data(), static_cast<Eigen::Index>(q.size()));
    seeded_ = true;
  }

  // One place: `joints` (rad) and/or `pose`; `what` names it in messages.
  void Resolve(const std::string& what, const ToolPose& pose, std::vector<double>* joints,
               std::vector<std::string>* notes, std::uint64_t seed) {
    const int nq = robot_.nq;
    std::optional<std::size_t> solved_note;
    if (joints->empty() && !pose.given()) return;  // an optional retreat not given
    if (static_cast<int>(joints->size()) == nq) {
      if (!pose.given()) return;
      const double dp = PositionError(*joints, pose), da = AxisError(*joints, pose);
      if (dp <= options_.position && da <= options_.axis) return;
      std::ostringstream s;
      s.precision(3);
      s << what << ": the joint positions put the end effector " << dp << " m and " << da
        << " rad from the pose; the pose was solved instead";
      notes->push_back(s.str());
      solved_note = notes->size() - 1;
    } else if (!pose.given()) {
      throw std::invalid_argument(what + ": " + std::to_string(joints->size()) + " joint positions, robot '" +
                                  robot_.name + "' has " + std::to_string(nq) + " joints: give the place as a pose too");
    } else if (!joints->empty()) {
      notes->push_back(what + ": " + std::to_string(joints->size()) + " joint positions, not for robot '" +
                       robot_.name + "' (" + std::to_string(nq) + " joints): the pose was solved instead");
      solved_note = notes->size() - 1;
    }
    *joints = Solve(what, pose, seed);
    std::ostringstream q;
    q.precision(4);
    for (std::size_t i = 0; i < joints->size(); ++i) q << (i ? ", " : "") << (*joints)[i];
    const std::string solved = " [" + q.str() + "] rad";
    if (solved_note) (*notes)[*solved_note] += solved;
    else notes->push_back(what + ": the pose solved for robot '" + robot_.name + "':" + solved);
  }

 private:
  Eigen::Isometry3d EndEffector(const std::vector<double>& q) {
    collision::CalcForwardKinematics(robot_, Eigen::Map<const Eigen::VectorXd>(q.data(), robot_.nq), &data_);
    Eigen::Isometry3d X = data_.X_WL[ee_link_];
    X.translation() = X * ee_offset_;
    return X;
  }
  double PositionError(const std::vector<double>& q, const ToolPose& pose) {
    return (EndEffector(q).translation() - Vec3(pose.position)).norm();
  }
  double AxisError(const std::vector<double>& q, const ToolPose& pose) {
    const Eigen::Vector3d z = EndEffector(q).linear().col(2);
    return std::acos(std::clamp(z.dot(Vec3(pose.z_axis).normalized()), -1.0, 1.0));
  }

  // IK along the straight line from the seed's end-effector pose to (p, z)
  // in small steps, no restarts; the end only if it is clear (Clearance).
  std::optional<Eigen::VectorXd> Continue(const Eigen::VectorXd& from, const Eigen::Vector3d& p, const Eigen::Vector3d& z,
                                         std::uint64_t seed) {
    const Eigen::Isometry3d X0 = EndEffector(std::vector<double>(from.data(), from.data() + from.size()));
    const Eigen::Vector3d p0 = X0.translation(), z0 = X0.linear().col(2);
    const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(z0, z);
    Eigen::VectorXd q = from;
    constexpr int kSteps = 20;
    planning::IkResult ik;
    for (int k = 1; k <= kSteps; ++k) {
      const double s = static_cast<double>(k) / kSteps;
      const Eigen::Vector3d zk = (Eigen::Quaterniond::Identity().slerp(s, turn) * z0).normalized();
      ik = planner_.SolveIkForToolAxis(p0 + s * (p - p0), zk, q, seed, /*restarts=*/0);
      if (!ik.success) return std::nullopt;
      q = ik.q;
    }
    if (Clearance(q) < 0.0) return std::nullopt;
    return q;
  }

  // How many of places_ are reached from q by Continue.
  std::size_t Reached(const Eigen::VectorXd& q) {
    std::size_t n = 0;
    for (const ToolPose& place : places_)
      n += Continue(q, Vec3(place.position), Vec3(place.z_axis).normalized(), 1).has_value() ? 1 : 0;
    return n;
  }

  // The smaller of the clearance from the static scene and from the arm
  // itself (m; negative: in collision; GoalOptions::self_overlap allowed).
  double Clearance(const Eigen::VectorXd& q) {
    // Sampled on first use: a graph whose places are all joints of this
    // robot never needs it.
    if (!self_) self_ = collision::ComputeSelfCollision(robot_);
    collision::CalcForwardKinematics(robot_, q, &data_);
    return std::min(planner_.CalcClearance(q), collision::SelfDistance(robot_, *self_, data_) + options_.self_overlap);
  }

  // A revolute joint at q + 2 pi k is the same pose: each joint takes the
  // turn nearest the seed that its limits allow.
  void NearestTurn(Eigen::VectorXd* q) const {
    const Eigen::VectorXd lo = robot_.LowerLimits(), hi = robot_.UpperLimits();
    for (int i = 0; i < robot_.nq; ++i) {
      if (robot_.joints[robot_.q_joints[i]].type != collision::JointType::kRevolute) continue;
      const double k = std::round((seed_[i] - (*q)[i]) / (2.0 * M_PI));
      for (double turn : {k, k - 1.0, k + 1.0}) {
        const double v = (*q)[i] + 2.0 * M_PI * turn;
        if (v >= lo[i] && v <= hi[i] && std::abs(v - seed_[i]) < std::abs((*q)[i] - seed_[i])) (*q)[i] = v;
      }
    }
  }

  // Sum of the links' horizontal distances (m) from the root's origin.
  double Reach(const Eigen::VectorXd& q) {
    collision::CalcForwardKinematics(robot_, q, &data_);
    double sum = 0.0;
    for (const Eigen::Isometry3d& X : data_.X_WL) sum += (X.translation() - data_.X_WL[0].translation()).head<2>().norm();
    return sum;
  }

  std::vector<double> Solve(const std::string& what, const ToolPose& pose, std::uint64_t seed) {
    const Eigen::Vector3d p = Vec3(pose.position), z = Vec3(pose.z_axis).normalized();
    double best_error = std::numeric_limits<double>::infinity(), best_clearance = -1.0;
    // From the seed and from seeds near it (a fixed stream), each with the
    // IK's own restarts: of the solutions that are clear (Clearance), the one
    // nearest the seed (the arm keeps its elbow and wrist from place to
    // place, so the optimiser can get there within its horizon).
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    std::optional<Eigen::VectorXd> best;
    double best_distance = std::numeric_limits<double>::infinity();
    if (seeded_) {
      // First along the straight way from the rest place, each step seeded
      // by the last: the solution the arm reaches without changing its
      // elbow or wrist (the optimiser's way there).
      if (std::optional<Eigen::VectorXd> q = Continue(seed_, p, z, seed); q) return std::vector<double>(q->data(), q->data() + q->size());
    }
    for (int attempt = 0; attempt < kAttempts; ++attempt) {
      Eigen::VectorXd start = seed_;
      for (Eigen::Index i = 0; i < start.size(); ++i) start[i] += attempt == 0 ? 0.0 : 0.4 * n(rng);
      start = start.cwiseMax(robot_.LowerLimits()).cwiseMin(robot_.UpperLimits());
      planning::IkResult ik = planner_.SolveIkForToolAxis(p, z, start, seed * 1000 + attempt);
      NearestTurn(&ik.q);
      best_error = std::min(best_error, ik.position_error);
      if (!ik.success) continue;
      const double clearance = Clearance(ik.q);
      if (clearance < 0.0) {
        best_clearance = std::max(best_clearance, clearance);
        continue;
      }
      // The rest place (no seed yet): the solution from which the most of
      // the other places are reached without changing elbow or wrist, then
      // the arm most gathered up over its base. Else: nearest the rest.
      const double distance =
          seeded_ ? (ik.q - seed_).cwiseAbs().maxCoeff() : 100.0 * (places_.size() - Reached(ik.q)) + Reach(ik.q);
      if (distance < best_distance) {
        best_distance = distance;
        best = ik.q;
      }
    }
    if (best) return std::vector<double>(best->data(), best->data() + best->size());
    std::ostringstream s;
    s.precision(3);
    s << what << ": robot '" << robot_.name << "' has no solution clear of the scene and of itself for position " << Text(p)
      << " m, z axis " << Text(z) << " (best position error " << best_error << " m";
    if (best_error <= planner_.params().ik_position_tolerance) s << ", best clearance " << best_clearance << " m";
    s << ")";
    throw std::invalid_argument(s.str());
  }

  const planning::Planner& planner_;
  const collision::RobotModel& robot_;
  collision::RobotData data_;
  GoalOptions options_;
  std::optional<collision::SelfCollisionModel> self_;  // the link pairs worth checking
  int ee_link_ = -1;
  Eigen::Vector3d ee_offset_;
  Eigen::VectorXd seed_;
  std::vector<ToolPose> places_;
  bool seeded_ = false;  // seed_ is the rest place (else the middle of the limits)
};

}  // namespace

std::vector<std::string> ResolveTaskGoals(const planning::Planner& planner, TaskGraph* graph,
                                          const GoalOptions& options) {
  if (const std::string why = graph->Validate(); !why.empty()) throw std::invalid_argument(why);
  Resolver resolver(planner, options);
  std::vector<ToolPose> places;
  for (const RobotTask& t : graph->tasks)
    for (const ToolPose* pose : {&t.goal_pose, &t.retreat_pose})
      if (pose->given() && t.name != graph->rest) places.push_back(*pose);
  resolver.SetPlaces(std::move(places));
  std::vector<std::string> notes;
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < graph->tasks.size(); ++i)
    if (graph->tasks[i].name == graph->rest) order.push_back(i);
  for (std::size_t i = 0; i < graph->tasks.size(); ++i)
    if (graph->tasks[i].name != graph->rest) order.push_back(i);
  for (std::size_t k = 0; k < order.size(); ++k) {
    RobotTask& t = graph->tasks[order[k]];
    const std::uint64_t seed = 2 * order[k] + 1;
    resolver.Resolve("task '" + t.name + "' goal", t.goal_pose, &t.goal, &notes, seed);
    if (t.name == graph->rest) resolver.SetSeed(t.goal);  // the others start from the rest
    resolver.Resolve("task '" + t.name + "' retreat", t.retreat_pose, &t.retreat, &notes, seed + 1);
  }
  return notes;
}

std::vector<double> RestPositions(const TaskGraph& graph) {
  for (const RobotTask& t : graph.tasks)
    if (t.name == graph.rest) return t.goal;
  return {};
}

}  // namespace iplan::supervisor

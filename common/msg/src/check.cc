#include "iplan/msg/check.h"

#include <cmath>
#include <cstdio>
#include <set>

namespace iplan::msg {
namespace {

std::string Num(double x) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%g", x);
  return buf;
}

// Fast test of what CheckCovariance reports (unrolled, no branches).
inline bool SymmetricPair(double a, double b) {
  return std::fabs(a - b) <= 1e-9 * (1 + std::fabs(a) + std::fabs(b));
}
inline bool CovarianceOk(const std::array<double, 9>& c) {
  return (c[0] >= 0) & (c[4] >= 0) & (c[8] >= 0) & SymmetricPair(c[1], c[3]) & SymmetricPair(c[2], c[6]) &
         SymmetricPair(c[5], c[7]) & (c[1] * c[1] <= c[0] * c[4] * (1 + 1e-9) + 1e-300) &
         (c[2] * c[2] <= c[0] * c[8] * (1 + 1e-9) + 1e-300) & (c[5] * c[5] <= c[4] * c[8] * (1 + 1e-9) + 1e-300);
}

// `path` is only called when there is something to report.
template <class PathFn>
std::optional<std::string> CheckCovariance(const std::array<double, 9>& c, PathFn path) {
  if (CovarianceOk(c)) return std::nullopt;
  for (int i = 0; i < 3; ++i) {
    if (c[i * 3 + i] < 0) return path() + ": negative variance " + Num(c[i * 3 + i]);
    for (int j = i + 1; j < 3; ++j) {
      const double a = c[i * 3 + j], b = c[j * 3 + i];
      if (std::abs(a - b) > 1e-9 * (1 + std::abs(a) + std::abs(b))) {
        return path() + ": not symmetric (" + Num(a) + " vs " + Num(b) + ")";
      }
      if (a * a > c[i * 3 + i] * c[j * 3 + j] * (1 + 1e-9) + 1e-300) {
        return path() + ": not positive semi-definite";
      }
    }
  }
  return std::nullopt;
}

template <class NameFn>
std::optional<std::string> CheckUnit(double x, NameFn what) {
  if (x < 0 || x > 1) return what() + " " + Num(x) + " outside [0, 1]";
  return std::nullopt;
}
std::optional<std::string> CheckUnit(double x, const char* what) {
  return CheckUnit(x, [what] { return std::string(what); });
}

}  // namespace

std::optional<std::string> CheckSemantics(const Header& m) {
  if (m.stamp.nanosec >= 1000000000u) return "header.stamp.nanosec >= 1e9";
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const HumanSkeleton& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.joints.empty()) return std::string("skeleton has no joints");
  if (auto e = CheckUnit(m.confidence, "confidence")) return e;
  for (std::size_t i = 0; i < m.joints.size(); ++i) {
    const auto& j = m.joints[i];
    auto path = [i] { return "joints[" + std::to_string(i) + "]"; };
    if (j.name.empty()) return path() + ": empty joint name";
    for (std::size_t k = 0; k < i; ++k) {
      if (m.joints[k].name == j.name) return path() + ": joint '" + j.name + "' appears twice";
    }
    if (auto e = CheckUnit(j.confidence, [&] { return path() + ".confidence"; })) return e;
    if (auto e = CheckCovariance(j.covariance, [&] { return path() + ".covariance"; })) return e;
  }
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const ActionBelief& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.observation_stamp.nanosec >= 1000000000u) return std::string("observation_stamp.nanosec >= 1e9");
  if (m.actions.size() != m.probabilities.size()) {
    return "probabilities has " + std::to_string(m.probabilities.size()) + " entries for " +
           std::to_string(m.actions.size()) + " actions";
  }
  double sum = 0;
  for (std::size_t i = 0; i < m.probabilities.size(); ++i) {
    if (auto e = CheckUnit(m.probabilities[i], [i] { return "probabilities[" + std::to_string(i) + "]"; })) return e;
    sum += m.probabilities[i];
  }
  if (!m.actions.empty() && std::abs(sum - 1) > 1e-3) return "probabilities sum to " + Num(sum);
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const HumanPrediction& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.observation_stamp.nanosec >= 1000000000u) return std::string("observation_stamp.nanosec >= 1e9");
  if (!(m.time_step > 0)) return "time_step " + Num(m.time_step) + " is not positive";
  const std::size_t expected = static_cast<std::size_t>(m.num_steps) * m.joint_names.size();
  double sum = 0;
  for (std::size_t a = 0; a < m.actions.size(); ++a) {
    const auto& act = m.actions[a];
    auto path = [a] { return "actions[" + std::to_string(a) + "]"; };
    if (auto e = CheckUnit(act.probability, [&] { return path() + ".probability"; })) return e;
    sum += act.probability;
    if (act.joints.size() != expected) {
      return path() + ".joints has " + std::to_string(act.joints.size()) + " entries, expected " +
             std::to_string(m.num_steps) + " steps x " + std::to_string(m.joint_names.size()) +
             " joints = " + std::to_string(expected);
    }
    bool all_ok = true;
    for (const auto& g : act.joints) all_ok &= CovarianceOk(g.covariance);
    if (!all_ok) {  // find and describe the first offender
      for (std::size_t k = 0; k < act.joints.size(); ++k) {
        if (auto e = CheckCovariance(act.joints[k].covariance, [&] {
              return path() + ".joints[" + std::to_string(k) + "].covariance";
            })) {
          return e;
        }
      }
    }
  }
  if (!m.actions.empty() && std::abs(sum - 1) > 1e-3) return "action probabilities sum to " + Num(sum);
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const JointState& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  const std::size_t n = m.name.size();
  auto bad = [n](const std::vector<double>& v) { return !v.empty() && v.size() != n; };
  if (bad(m.position)) return "position has " + std::to_string(m.position.size()) + " entries for " + std::to_string(n) + " names";
  if (bad(m.velocity)) return "velocity has " + std::to_string(m.velocity.size()) + " entries for " + std::to_string(n) + " names";
  if (bad(m.effort)) return "effort has " + std::to_string(m.effort.size()) + " entries for " + std::to_string(n) + " names";
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const JointTrajectory& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  const std::size_t n = m.joint_names.size();
  double last = -1;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const auto& p = m.points[i];
    auto path = [i] { return "points[" + std::to_string(i) + "]"; };
    if (p.positions.size() != n) {
      return path() + ".positions has " + std::to_string(p.positions.size()) + " entries for " +
             std::to_string(n) + " joints";
    }
    if (!p.velocities.empty() && p.velocities.size() != n) return path() + ".velocities has the wrong size";
    if (!p.accelerations.empty() && p.accelerations.size() != n) return path() + ".accelerations has the wrong size";
    if (!p.effort.empty() && p.effort.size() != n) return path() + ".effort has the wrong size";
    if (p.time_from_start.nanosec >= 1000000000u) return path() + ".time_from_start.nanosec >= 1e9";
    const double t = p.time_from_start.sec + p.time_from_start.nanosec * 1e-9;
    if (t <= last) return path() + ".time_from_start does not increase";
    last = t;
  }
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const PointCloud2& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (static_cast<uint64_t>(m.point_step) * m.width > m.row_step) return std::string("point_step * width exceeds row_step");
  if (static_cast<uint64_t>(m.row_step) * m.height != m.data.size()) {
    return "data has " + std::to_string(m.data.size()) + " bytes, expected row_step * height = " +
           std::to_string(static_cast<uint64_t>(m.row_step) * m.height);
  }
  for (const auto& f : m.fields) {
    if (f.datatype < 1 || f.datatype > 8) return "field '" + f.name + "' has datatype " + std::to_string(f.datatype);
  }
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const TaskCommand& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.command > TaskCommand::CANCEL) return "command " + std::to_string(m.command) + " unknown";
  if (m.goal_type > TaskCommand::GOAL_POSE) return "goal_type " + std::to_string(m.goal_type) + " unknown";
  if (m.command == TaskCommand::START && m.goal_type == TaskCommand::GOAL_JOINTS && m.goal_positions.empty()) {
    return std::string("joint goal without goal_positions");
  }
  if (m.time_limit < 0) return "time_limit " + Num(m.time_limit) + " is negative";
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const TaskOutcome& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.status > TaskOutcome::CANCELLED) return "status " + std::to_string(m.status) + " unknown";
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const PlanStatus& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.latency < 0) return "latency " + Num(m.latency) + " is negative";
  if (m.planning_time < 0) return "planning_time " + Num(m.planning_time) + " is negative";
  if (auto e = CheckUnit(m.max_bound, [] { return std::string("max_bound"); })) return e;
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const CollisionRisk& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.verdict > CollisionRisk::PROTECTIVE_STOP) return "verdict " + std::to_string(m.verdict) + " unknown";
  for (std::size_t i = 0; i < m.waypoint_bounds.size(); ++i) {
    if (auto e = CheckUnit(m.waypoint_bounds[i], [i] { return "waypoint_bounds[" + std::to_string(i) + "]"; })) return e;
  }
  if (!m.waypoint_bounds.empty() && m.max_waypoint >= m.waypoint_bounds.size()) return std::string("max_waypoint out of range");
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const SafetyPermit& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.state > SafetyPermit::PERMIT) return "state " + std::to_string(m.state) + " unknown";
  if (!(m.validity > 0) || m.validity > 10) return "validity " + Num(m.validity) + " s outside (0, 10]";
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const DiagnosticArray& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  for (std::size_t i = 0; i < m.status.size(); ++i) {
    if (m.status[i].level > DiagnosticStatus::STALE) return "status[" + std::to_string(i) + "].level unknown";
  }
  return std::nullopt;
}

}  // namespace iplan::msg

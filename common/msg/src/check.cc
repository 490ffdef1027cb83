#include "iplan/msg/check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <utility>
#include <vector>

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

// "<field> has <n> <unit>, limit <limit>": names the field and the limit, so
// the sender can tell which rule it broke.
std::string Over(const std::string& field, uint64_t n, uint64_t limit, const char* unit = "entries") {
  return field + " has " + std::to_string(n) + " " + unit + ", limit " + std::to_string(limit);
}

// `field` is only called when there is something to report.
template <class FieldFn>
std::optional<std::string> CheckLength(const std::string& s, std::size_t limit, FieldFn field) {
  if (s.size() > limit) return Over(field(), s.size(), limit, "characters");
  return std::nullopt;
}
std::optional<std::string> CheckLength(const std::string& s, std::size_t limit, const char* field) {
  return CheckLength(s, limit, [field] { return std::string(field); });
}

// A sequence of at most `count` names of at most Limits::kName characters.
std::optional<std::string> CheckNames(const std::vector<std::string>& v, std::size_t count, const char* field) {
  if (v.size() > count) return Over(field, v.size(), count);
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (auto e = CheckLength(v[i], Limits::kName, [&] { return std::string(field) + "[" + std::to_string(i) + "]"; })) {
      return e;
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> CheckSizes(const Header& m) {
  return CheckLength(m.frame_id, Limits::kName, "header.frame_id");
}

std::optional<std::string> CheckSizes(const HumanSkeleton& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (m.joints.size() > Limits::kSkeletonJoints) return Over("joints", m.joints.size(), Limits::kSkeletonJoints);
  for (std::size_t i = 0; i < m.joints.size(); ++i) {
    auto field = [i] { return "joints[" + std::to_string(i) + "].name"; };
    if (auto e = CheckLength(m.joints[i].name, Limits::kName, field)) return e;
  }
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const ActionBelief& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (auto e = CheckNames(m.actions, Limits::kActions, "actions")) return e;
  if (m.probabilities.size() > Limits::kActions) return Over("probabilities", m.probabilities.size(), Limits::kActions);
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const HumanPrediction& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (m.num_steps > Limits::kPredictionSteps) {
    return "num_steps is " + std::to_string(m.num_steps) + ", limit " + std::to_string(Limits::kPredictionSteps);
  }
  if (auto e = CheckNames(m.joint_names, Limits::kPredictionJoints, "joint_names")) return e;
  if (m.actions.size() > Limits::kActions) return Over("actions", m.actions.size(), Limits::kActions);
  // Each factor is bounded now, so the product cannot wrap.
  const uint64_t declared = uint64_t{m.num_steps} * m.joint_names.size() * m.actions.size();
  if (declared > Limits::kPredictionGaussians) {
    return "actions x num_steps x joint_names = " + std::to_string(declared) + " Gaussians, limit " +
           std::to_string(Limits::kPredictionGaussians);
  }
  // What is sent may differ from what is declared (CheckSemantics tells);
  // the walk over it must be bounded all the same.
  uint64_t sent = 0;
  for (std::size_t a = 0; a < m.actions.size(); ++a) {
    auto field = [a] { return "actions[" + std::to_string(a) + "].action"; };
    if (auto e = CheckLength(m.actions[a].action, Limits::kName, field)) return e;
    sent += m.actions[a].joints.size();
  }
  if (sent > Limits::kPredictionGaussians) return Over("actions[].joints", sent, Limits::kPredictionGaussians);
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const JointState& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (auto e = CheckNames(m.name, Limits::kRobotJoints, "name")) return e;
  if (m.position.size() > Limits::kRobotJoints) return Over("position", m.position.size(), Limits::kRobotJoints);
  if (m.velocity.size() > Limits::kRobotJoints) return Over("velocity", m.velocity.size(), Limits::kRobotJoints);
  if (m.effort.size() > Limits::kRobotJoints) return Over("effort", m.effort.size(), Limits::kRobotJoints);
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const JointTrajectory& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (auto e = CheckNames(m.joint_names, Limits::kRobotJoints, "joint_names")) return e;
  if (m.points.size() > Limits::kTrajectoryPoints) return Over("points", m.points.size(), Limits::kTrajectoryPoints);
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const auto& p = m.points[i];
    const std::pair<const char*, const std::vector<double>*> values[] = {
        {"positions", &p.positions},
        {"velocities", &p.velocities},
        {"accelerations", &p.accelerations},
        {"effort", &p.effort}};
    for (const auto& [field, v] : values) {
      if (v->size() > Limits::kRobotJoints) {
        return Over("points[" + std::to_string(i) + "]." + field, v->size(), Limits::kRobotJoints);
      }
    }
  }
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const PointCloud2& m) {
  if (auto e = CheckSizes(m.header)) return e;
  const uint64_t points = uint64_t{m.width} * m.height;  // both 32-bit: cannot wrap
  if (points > Limits::kCloudPoints) {
    return "width x height = " + std::to_string(points) + " points, limit " + std::to_string(Limits::kCloudPoints);
  }
  if (m.point_step > Limits::kCloudPointStep) {
    return "point_step is " + std::to_string(m.point_step) + " bytes, limit " + std::to_string(Limits::kCloudPointStep);
  }
  if (m.data.size() > Limits::kCloudBytes) return Over("data", m.data.size(), Limits::kCloudBytes, "bytes");
  if (m.fields.size() > Limits::kCloudFields) return Over("fields", m.fields.size(), Limits::kCloudFields);
  for (std::size_t i = 0; i < m.fields.size(); ++i) {
    auto field = [i] { return "fields[" + std::to_string(i) + "].name"; };
    if (auto e = CheckLength(m.fields[i].name, Limits::kName, field)) return e;
  }
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const Image& m) {
  if (auto e = CheckSizes(m.header)) return e;
  const uint64_t pixels = uint64_t{m.width} * m.height;  // both 32-bit: cannot wrap
  if (pixels > Limits::kCloudPoints) {
    return "width x height = " + std::to_string(pixels) + " pixels, limit " + std::to_string(Limits::kCloudPoints);
  }
  if (auto e = CheckLength(m.encoding, Limits::kName, "encoding")) return e;
  if (m.data.size() > Limits::kImageBytes) return Over("data", m.data.size(), Limits::kImageBytes, "bytes");
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const CameraInfo& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (auto e = CheckLength(m.distortion_model, Limits::kName, "distortion_model")) return e;
  if (m.d.size() > Limits::kDistortionCoefficients) return Over("d", m.d.size(), Limits::kDistortionCoefficients);
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const TFMessage& m) {
  if (m.transforms.size() > Limits::kTransforms) return Over("transforms", m.transforms.size(), Limits::kTransforms);
  for (std::size_t i = 0; i < m.transforms.size(); ++i) {
    const auto field = [&](const char* f) { return "transforms[" + std::to_string(i) + "]." + f; };
    if (auto e = CheckLength(m.transforms[i].header.frame_id, Limits::kName, [&] { return field("header.frame_id"); })) {
      return e;
    }
    if (auto e = CheckLength(m.transforms[i].child_frame_id, Limits::kName, [&] { return field("child_frame_id"); })) {
      return e;
    }
  }
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const ObstacleArray& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (m.obstacles.size() > Limits::kObstacles) return Over("obstacles", m.obstacles.size(), Limits::kObstacles);
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const HumanPoints& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (m.points.size() > Limits::kHumanPoints) return Over("points", m.points.size(), Limits::kHumanPoints);
  if (m.motions.size() > Limits::kPointMotions) return Over("motions", m.motions.size(), Limits::kPointMotions);
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const TaskCommand& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (auto e = CheckLength(m.task_name, Limits::kName, "task_name")) return e;
  if (m.goal_positions.size() > Limits::kRobotJoints) {
    return Over("goal_positions", m.goal_positions.size(), Limits::kRobotJoints);
  }
  if (m.retreat_positions.size() > Limits::kRobotJoints) {
    return Over("retreat_positions", m.retreat_positions.size(), Limits::kRobotJoints);
  }
  return std::nullopt;
}

std::optional<std::string> CheckSizes(const TaskOutcome& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (auto e = CheckLength(m.task_name, Limits::kName, "task_name")) return e;
  return CheckLength(m.reason, Limits::kText, "reason");
}

std::optional<std::string> CheckSizes(const PlanStatus& m) {
  if (auto e = CheckSizes(m.header)) return e;
  return CheckLength(m.status, Limits::kText, "status");
}

std::optional<std::string> CheckSizes(const CollisionRisk& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (m.waypoint_bounds.size() > Limits::kTrajectoryPoints) {
    return Over("waypoint_bounds", m.waypoint_bounds.size(), Limits::kTrajectoryPoints);
  }
  if (auto e = CheckLength(m.max_robot_link, Limits::kName, "max_robot_link")) return e;
  if (auto e = CheckLength(m.max_human_segment, Limits::kName, "max_human_segment")) return e;
  if (auto e = CheckLength(m.max_action, Limits::kName, "max_action")) return e;
  return CheckLength(m.reason, Limits::kText, "reason");
}

std::optional<std::string> CheckSizes(const SafetyPermit& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (auto e = CheckLength(m.source, Limits::kName, "source")) return e;
  return CheckLength(m.reason, Limits::kText, "reason");
}

std::optional<std::string> CheckSizes(const DiagnosticArray& m) {
  if (auto e = CheckSizes(m.header)) return e;
  if (m.status.size() > Limits::kDiagnosticStatuses) {
    return Over("status", m.status.size(), Limits::kDiagnosticStatuses);
  }
  for (std::size_t i = 0; i < m.status.size(); ++i) {
    const auto& st = m.status[i];
    auto path = [i] { return "status[" + std::to_string(i) + "]"; };
    if (auto e = CheckLength(st.name, Limits::kName, [&] { return path() + ".name"; })) return e;
    if (auto e = CheckLength(st.hardware_id, Limits::kName, [&] { return path() + ".hardware_id"; })) return e;
    if (auto e = CheckLength(st.message, Limits::kText, [&] { return path() + ".message"; })) return e;
    if (st.values.size() > Limits::kDiagnosticValues) {
      return Over(path() + ".values", st.values.size(), Limits::kDiagnosticValues);
    }
    for (std::size_t k = 0; k < st.values.size(); ++k) {
      auto value = [&] { return path() + ".values[" + std::to_string(k) + "]"; };
      if (auto e = CheckLength(st.values[k].key, Limits::kName, [&] { return value() + ".key"; })) return e;
      if (auto e = CheckLength(st.values[k].value, Limits::kText, [&] { return value() + ".value"; })) return e;
    }
  }
  return std::nullopt;
}

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
    if (auto e = CheckUnit(j.confidence, [&] { return path() + ".confidence"; })) return e;
    if (auto e = CheckCovariance(j.covariance, [&] { return path() + ".covariance"; })) return e;
  }
  // Duplicates in O(n log n): joint indices sorted by (name, index), on the
  // stack (CheckSizes bounds n; a caller that skipped it is refused here).
  if (m.joints.size() > Limits::kSkeletonJoints) return Over("joints", m.joints.size(), Limits::kSkeletonJoints);
  static_assert(Limits::kSkeletonJoints <= UINT16_MAX, "joint indices are 16-bit");
  std::array<uint16_t, Limits::kSkeletonJoints> order;
  const auto n = static_cast<uint16_t>(m.joints.size());
  for (uint16_t i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.begin() + n, [&m](uint16_t a, uint16_t b) {
    const int c = m.joints[a].name.compare(m.joints[b].name);
    return c < 0 || (c == 0 && a < b);
  });
  // Report the first joint, in message order, whose name came before.
  std::size_t repeat = n;
  for (uint16_t k = 1; k < n; ++k) {
    if (m.joints[order[k]].name == m.joints[order[k - 1]].name) repeat = std::min<std::size_t>(repeat, order[k]);
  }
  if (repeat < n) {
    return "joints[" + std::to_string(repeat) + "]: joint '" + m.joints[repeat].name + "' appears twice";
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
  // Unsigned wrap-around is defined, so test the product after the fact;
  // CheckSizes bounds both factors, but this holds without it too.
  if (!m.joint_names.empty() && expected / m.joint_names.size() != m.num_steps) {
    return "num_steps " + std::to_string(m.num_steps) + " x " + std::to_string(m.joint_names.size()) +
           " joint_names overflows";
  }
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

std::optional<std::string> CheckSemantics(const Image& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (static_cast<uint64_t>(m.step) * m.height != m.data.size()) {
    return "data has " + std::to_string(m.data.size()) + " bytes, expected step * height = " +
           std::to_string(static_cast<uint64_t>(m.step) * m.height);
  }
  return std::nullopt;
}

// What the calibration means (a pinhole, rectified or not) is the
// consumer's to judge (services::FromCameraInfo); here only the header.
std::optional<std::string> CheckSemantics(const CameraInfo& m) { return CheckSemantics(m.header); }

std::optional<std::string> CheckSemantics(const ObstacleArray& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  for (std::size_t i = 0; i < m.obstacles.size(); ++i) {
    const Obstacle& o = m.obstacles[i];
    if (o.id == 0) return "obstacles[" + std::to_string(i) + "].id is 0";
    const auto& q = o.orientation;
    const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (std::abs(norm - 1.0) > 1e-3) {
      return "obstacles[" + std::to_string(i) + "].orientation is not a unit quaternion (norm " + Num(norm) + ")";
    }
    for (double h : o.half_extents) {
      if (h < 0) return "obstacles[" + std::to_string(i) + "].half_extents has " + Num(h);
    }
  }
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const HumanPoints& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.voxel_size < 0) return "voxel_size " + Num(m.voxel_size) + " is negative";
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    auto path = [i] { return "points[" + std::to_string(i) + "].covariance"; };
    if (auto e = CheckCovariance(m.points[i].covariance, path)) return e;
    if (m.points[i].motion > m.motions.size()) {
      return "points[" + std::to_string(i) + "].motion " + std::to_string(m.points[i].motion) + " names no motion (" +
             std::to_string(m.motions.size()) + " motions)";
    }
  }
  std::vector<uint32_t> ids;
  ids.reserve(m.motions.size());
  for (std::size_t k = 0; k < m.motions.size(); ++k) {
    auto path = [k] { return "motions[" + std::to_string(k) + "].velocity_covariance"; };
    if (auto e = CheckCovariance(m.motions[k].velocity_covariance, path)) return e;
    if (m.motions[k].id == 0) return "motions[" + std::to_string(k) + "].id is 0";
    ids.push_back(m.motions[k].id);
  }
  std::sort(ids.begin(), ids.end());
  if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) return std::string("motions has a repeated id");
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
  if (auto e = CheckUnit(m.speed_scale, "speed_scale")) return e;
  return std::nullopt;
}

std::optional<std::string> CheckSemantics(const SafetyPermit& m) {
  if (auto e = CheckSemantics(m.header)) return e;
  if (m.state > SafetyPermit::PERMIT) return "state " + std::to_string(m.state) + " unknown";
  if (!(m.validity > 0) || m.validity > 10) return "validity " + Num(m.validity) + " s outside (0, 10]";
  if (!(m.speed_reduction >= 0 && m.speed_reduction <= 1)) {
    return "speed_reduction " + Num(m.speed_reduction) + " outside [0, 1]";
  }
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

#include "iplan/adapters/adapters.h"

#include <algorithm>
#include <limits>

#include "iplan/cell/joint_trajectory.h"
#include "iplan/msg/check.h"
#include "iplan/msg/time.h"

namespace iplan::services {

std::array<double, 9> ToWireCovariance(const Eigen::Matrix3d& c) {
  std::array<double, 9> w;
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(w.data()) = c;
  return w;
}

Eigen::Matrix3d FromWireCovariance(const std::array<double, 9>& w) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(w.data());
}

collision::JointMixture ToJointMixture(const msg::HumanPrediction& m) {
  collision::JointMixture in;
  in.t0_ns = msg::ToNanoseconds(m.observation_stamp);
  in.time_step = m.time_step;
  in.num_steps = static_cast<int>(m.num_steps);
  in.joint_names = m.joint_names;
  for (const auto& a : m.actions) {
    in.actions.push_back(a.action);
    in.probabilities.push_back(a.probability);
    std::vector<Eigen::Vector3d> means;
    std::vector<Eigen::Matrix3d> covs;
    means.reserve(a.joints.size());
    covs.reserve(a.joints.size());
    for (const auto& g : a.joints) {
      means.emplace_back(g.mean.x, g.mean.y, g.mean.z);
      covs.push_back(FromWireCovariance(g.covariance));
    }
    in.means.push_back(std::move(means));
    in.covariances.push_back(std::move(covs));
  }
  return in;
}

void FillPrediction(const collision::JointMixture& in, msg::HumanPrediction* m) {
  m->actions.resize(in.actions.size());
  for (std::size_t c = 0; c < in.actions.size(); ++c) {
    msg::ActionPrediction& a = m->actions[c];
    a.action = in.actions[c];
    a.probability = in.probabilities[c];
    a.joints.resize(in.means[c].size());
    for (std::size_t k = 0; k < in.means[c].size(); ++k) {  // both step-major
      const Eigen::Vector3d& mean = in.means[c][k];
      a.joints[k].mean = {mean.x(), mean.y(), mean.z()};
      a.joints[k].covariance = ToWireCovariance(in.covariances[c][k]);
    }
  }
}

cell::HumanPoints FromHumanPoints(const msg::HumanPoints& m) {
  cell::HumanPoints p;
  p.stamp_ns = msg::ToNanoseconds(m.header.stamp);
  p.voxel_size = m.voxel_size;
  p.means.resize(3, static_cast<Eigen::Index>(m.points.size()));
  p.covariances.resize(m.points.size());
  bool tracked = false;
  for (std::size_t i = 0; i < m.points.size(); ++i) {
    const msg::PointGaussian& g = m.points[i];
    p.means.col(static_cast<Eigen::Index>(i)) = Eigen::Vector3d(g.mean.x, g.mean.y, g.mean.z);
    p.covariances[i] = FromWireCovariance(g.covariance);
    tracked = tracked || g.motion > 0;
  }
  if (tracked) {
    p.motion_of.resize(m.points.size());
    for (std::size_t i = 0; i < m.points.size(); ++i) p.motion_of[i] = static_cast<int>(m.points[i].motion) - 1;
  }
  for (const msg::PointMotion& pm : m.motions) {
    p.motions.push_back({Eigen::Vector3d(pm.velocity.x, pm.velocity.y, pm.velocity.z),
                         FromWireCovariance(pm.velocity_covariance), pm.id});
  }
  return p;
}

void ToHumanPoints(const cell::HumanPoints& p, const msg::Time& stamp, const std::string& frame_id,
                   msg::HumanPoints* m) {
  m->header.stamp = stamp;
  m->header.frame_id = frame_id;
  m->voxel_size = p.voxel_size;
  m->points.clear();
  for (int i = 0; i < p.size(); ++i) {
    if (m->points.size() >= msg::Limits::kHumanPoints) break;
    msg::PointGaussian g;
    const auto mean = p.means.col(i);
    g.mean = {mean.x(), mean.y(), mean.z()};
    g.covariance = ToWireCovariance(p.covariances[static_cast<std::size_t>(i)]);
    const int k = p.MotionIndexOf(i);
    g.motion = k >= 0 && static_cast<std::size_t>(k) < msg::Limits::kPointMotions ? static_cast<uint32_t>(k + 1) : 0;
    m->points.push_back(g);
  }
  m->motions.clear();
  for (const cell::PointMotion& pm : p.motions) {
    if (m->motions.size() >= msg::Limits::kPointMotions) break;
    msg::PointMotion w;
    w.id = pm.id;
    w.velocity = {pm.velocity.x(), pm.velocity.y(), pm.velocity.z()};
    w.velocity_covariance = ToWireCovariance(pm.covariance);
    m->motions.push_back(w);
  }
}

std::vector<cell::ObstacleBox> FromObstacles(const msg::ObstacleArray& m) {
  std::vector<cell::ObstacleBox> out;
  out.reserve(m.obstacles.size());
  for (const msg::Obstacle& o : m.obstacles) {
    cell::ObstacleBox b;
    b.id = o.id;
    b.centre = {o.centre.x, o.centre.y, o.centre.z};
    b.orientation = Eigen::Quaterniond(o.orientation.w, o.orientation.x, o.orientation.y, o.orientation.z);
    b.half_extents = {o.half_extents[0], o.half_extents[1], o.half_extents[2]};
    b.points = static_cast<int>(std::min<uint32_t>(o.points, std::numeric_limits<int>::max()));
    b.first_seen_ns = msg::ToNanoseconds(o.first_seen);
    out.push_back(b);
  }
  return out;
}

void ToObstacles(const std::vector<cell::ObstacleBox>& boxes, const msg::Time& stamp, const std::string& frame_id,
                 msg::ObstacleArray* m) {
  m->header.stamp = stamp;
  m->header.frame_id = frame_id;
  m->obstacles.clear();
  for (const cell::ObstacleBox& b : boxes) {
    if (m->obstacles.size() >= msg::Limits::kObstacles) break;
    msg::Obstacle o;
    o.id = b.id;
    o.centre = {b.centre.x(), b.centre.y(), b.centre.z()};
    o.orientation = {b.orientation.x(), b.orientation.y(), b.orientation.z(), b.orientation.w()};
    o.half_extents = {b.half_extents.x(), b.half_extents.y(), b.half_extents.z()};
    o.points = static_cast<uint32_t>(std::max(0, b.points));
    o.first_seen = msg::TimeFromNanoseconds(b.first_seen_ns);
    m->obstacles.push_back(o);
  }
}

void FromTrajectory(const msg::JointTrajectory& m, std::vector<double>* times,
                    std::vector<std::vector<double>>* positions) {
  times->clear();
  positions->clear();
  for (const auto& p : m.points) {
    times->push_back(msg::ToSeconds(p.time_from_start));
    positions->push_back(p.positions);
  }
}

msg::JointTrajectory ToTrajectory(int64_t start_ns, const std::vector<std::string>& joint_names,
                                  const Eigen::MatrixXd& positions, double dt, const TrajectoryOutput& out,
                                  int64_t publish_ns) {
  msg::JointTrajectory t;
  t.header.stamp = out.zero_stamp ? msg::Time{} : msg::TimeFromNanoseconds(start_ns);
  t.header.frame_id = "world";
  t.joint_names = joint_names;
  const Eigen::Index n = positions.cols();
  if (n == 0) return t;
  Eigen::MatrixXd segment;  // forward differences, one per segment
  if (n >= 2) cell::FiniteDifferenceVelocities(positions, dt, &segment);
  Eigen::Index total = n;  // with the held last position
  while (static_cast<double>(total - 1) * dt < out.min_duration - 1e-9) ++total;
  const double t0 = out.zero_stamp ? 1e-9 * static_cast<double>(start_ns - publish_ns) : 0.0;
  for (Eigen::Index i = 0; i < total; ++i) {
    const double time = t0 + static_cast<double>(i) * dt;
    // Starting on receipt, the points already past are dropped (the
    // controller moves from where the robot is to the first one).
    if (out.zero_stamp && time <= 0.0 && i + 1 < total) continue;
    msg::JointTrajectoryPoint p;
    const Eigen::Index k = std::min(i, n - 1);
    p.positions.assign(positions.col(k).data(), positions.col(k).data() + positions.rows());
    if (out.velocities) {
      Eigen::VectorXd v = Eigen::VectorXd::Zero(positions.rows());
      if (n >= 2 && i < n) {
        if (i == 0) {
          v = segment.col(0);
        } else if (i < n - 1) {
          v = 0.5 * (segment.col(i - 1) + segment.col(i));
        } else if (total == n) {
          v = segment.col(n - 2);  // the end, one-sided; held after it: stays zero
        }
      }
      p.velocities.assign(v.data(), v.data() + v.size());
    }
    p.time_from_start = msg::DurationFromSeconds(std::max(time, 0.0));
    t.points.push_back(std::move(p));
  }
  return t;
}

int64_t TrajectoryStartNs(const msg::JointTrajectory& m, int64_t reception_ns) {
  const int64_t stamp = msg::ToNanoseconds(m.header.stamp);
  return stamp == 0 ? reception_ns : stamp;
}

double ToWire(const safety::Separation& s) { return s.value_or(kWireNoPerson); }

uint8_t ToWire(cell::Verdict v) {
  switch (v) {
    case cell::Verdict::kOk: return msg::CollisionRisk::OK;
    case cell::Verdict::kSlowDown: return msg::CollisionRisk::SLOW_DOWN;
    case cell::Verdict::kProtectiveStop: return msg::CollisionRisk::PROTECTIVE_STOP;
  }
  return msg::CollisionRisk::PROTECTIVE_STOP;
}

std::optional<cell::Verdict> VerdictFromWire(uint8_t octet) {
  switch (octet) {
    case msg::CollisionRisk::OK: return cell::Verdict::kOk;
    case msg::CollisionRisk::SLOW_DOWN: return cell::Verdict::kSlowDown;
    case msg::CollisionRisk::PROTECTIVE_STOP: return cell::Verdict::kProtectiveStop;
    default: return std::nullopt;
  }
}

uint8_t ToWire(cell::TaskStatus s) {
  switch (s) {
    case cell::TaskStatus::kSucceeded: return msg::TaskOutcome::SUCCEEDED;
    case cell::TaskStatus::kFailed: return msg::TaskOutcome::FAILED;
    case cell::TaskStatus::kCancelled: return msg::TaskOutcome::CANCELLED;
  }
  return msg::TaskOutcome::FAILED;
}

std::optional<cell::TaskStatus> TaskStatusFromWire(uint8_t octet) {
  switch (octet) {
    case msg::TaskOutcome::SUCCEEDED: return cell::TaskStatus::kSucceeded;
    case msg::TaskOutcome::FAILED: return cell::TaskStatus::kFailed;
    case msg::TaskOutcome::CANCELLED: return cell::TaskStatus::kCancelled;
    default: return std::nullopt;
  }
}

}  // namespace iplan::services

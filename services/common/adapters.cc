#include "adapters.h"

#include "iplan/msg/time.h"

namespace iplan::services {

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
      covs.push_back(Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(g.covariance.data()));
    }
    in.means.push_back(std::move(means));
    in.covariances.push_back(std::move(covs));
  }
  return in;
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

msg::JointTrajectory ToTrajectory(const msg::Time& start, const std::vector<std::string>& joint_names,
                                  const Eigen::MatrixXd& positions, double dt) {
  msg::JointTrajectory t;
  t.header.stamp = start;
  t.header.frame_id = "world";
  t.joint_names = joint_names;
  t.points.resize(static_cast<std::size_t>(positions.cols()));
  for (Eigen::Index i = 0; i < positions.cols(); ++i) {
    auto& p = t.points[static_cast<std::size_t>(i)];
    p.positions.assign(positions.col(i).data(), positions.col(i).data() + positions.rows());
    p.time_from_start = msg::DurationFromSeconds(static_cast<double>(i) * dt);
  }
  return t;
}

double ToWire(const cell::Separation& s) { return s.value_or(kWireNoPerson); }

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

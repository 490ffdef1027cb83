// Conversions between message types and the plain types of the algorithm
// cores, shared by the services (the only place where both meet).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/cell/human_points.h"
#include "iplan/cell/obstacle_box.h"
#include "iplan/safety/ssm.h"
#include "iplan/core/name_value.h"
#include "iplan/cell/status.h"
#include "iplan/collision/joint_mixture.h"
#include "iplan/msg/types.h"

namespace iplan::services {

/// The wire's 3x3 covariance (and velocity covariance) layout, the one place
/// that knows it: 9 values, row-major (idl/iplan_msgs.idl).
std::array<double, 9> ToWireCovariance(const Eigen::Matrix3d& c);
Eigen::Matrix3d FromWireCovariance(const std::array<double, 9>& w);

/// The joint-level mixture of a prediction message.
collision::JointMixture ToJointMixture(const msg::HumanPrediction& m);

/// The other way: the mixture's actions, probabilities and Gaussians into
/// `m`, reusing its storage. The header, the
/// observation stamp, the body id, the joint names, the time step and the
/// number of steps are the caller's (the intent service sets them once).
void FillPrediction(const collision::JointMixture& in, msg::HumanPrediction* m);

/// The people the depth camera sees (a point's
/// `motion` k >= 1 is motions[k - 1], 0 not tracked). The boundary has
/// checked the message (finite, covariances PSD, motion indices in range).
cell::HumanPoints FromHumanPoints(const msg::HumanPoints& m);
/// The other way, as the cloud service publishes them: at most
/// msg::Limits::kHumanPoints points and kPointMotions motions (a point whose
/// motion is not written goes out untracked); the stamp and frame are the
/// cloud's, as ToObstacles'.
void ToHumanPoints(const cell::HumanPoints& p, const msg::Time& stamp, const std::string& frame_id,
                   msg::HumanPoints* m);

/// The static obstacles of one cloud, both ways. The boundary has checked
/// a received message (ids >= 1, unit orientations, half extents >= 0);
/// ToObstacles writes at most msg::Limits::kObstacles of them.
std::vector<cell::ObstacleBox> FromObstacles(const msg::ObstacleArray& m);
void ToObstacles(const std::vector<cell::ObstacleBox>& boxes, const msg::Time& stamp, const std::string& frame_id,
                 msg::ObstacleArray* m);

/// Trajectory points as (times in s from header.stamp, positions per point).
void FromTrajectory(const msg::JointTrajectory& m, std::vector<double>* times,
                    std::vector<std::vector<double>>* positions);

/// How trajectories go out (trajopt's `output` settings, docs/topics.md).
struct TrajectoryOutput {
  /// header.stamp 0: "start on receipt", ros2_control's
  /// joint_trajectory_controller convention (robust to latency and to a
  /// controller on sim time); the points are re-timed from the publication
  /// time and those already past dropped. false: header.stamp is the time of
  /// waypoint 0 (iplan's convention, exact on synchronised clocks).
  bool zero_stamp = false;
  /// s; a shorter trajectory (e.g. a hold, 2 points over 0.1 s) is extended
  /// by holding its last position, at the same step, until this long, so a
  /// controller does not drop it as ended with a little latency.
  double min_duration = 0.0;
  /// Fill velocities (rad/s) from the positions (central differences inside,
  /// one-sided at the ends, zero where the last position is held).
  bool velocities = true;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(zero_stamp, "header.stamp 0 (start on receipt, the joint_trajectory_controller way); false: the time of waypoint 0"));
    a->Visit(IPLAN_NVP(min_duration, "s; shorter trajectories are extended by holding their last position, in [0, 60]"));
    a->Visit(IPLAN_NVP(velocities, "fill velocities from the positions"));
  }
  /// "" when valid, else the reason.
  std::string Validate() const {
    if (!(min_duration >= 0.0 && min_duration <= 60.0)) return "output.min_duration must be in [0, 60] s";
    return "";
  }
};

/// A trajectory message: `positions` is nq x (n + 1), waypoint i at
/// `start_ns` + i * dt (ns since the epoch; dt in s), shaped by `out`;
/// `publish_ns` is the publication time (used when out.zero_stamp).
msg::JointTrajectory ToTrajectory(int64_t start_ns, const std::vector<std::string>& joint_names,
                                  const Eigen::MatrixXd& positions, double dt, const TrajectoryOutput& out,
                                  int64_t publish_ns);

/// When a received trajectory's waypoint 0 is (ns since the epoch): its
/// header.stamp, or `reception_ns` when that is zero ("start on receipt").
int64_t TrajectoryStartNs(const msg::JointTrajectory& m, int64_t reception_ns);

/// The separation fields of CollisionRisk on the wire: metres, or
/// kWireNoPerson when no person is seen (idl/iplan_msgs.idl).
constexpr double kWireNoPerson = 1e6;
double ToWire(const safety::Separation& s);

/// Status octets by name (CollisionRisk::OK.., TaskOutcome::SUCCEEDED..).
/// FromWire of an octet the IDL does not define returns nullopt (the
/// message boundary refuses those before they reach a service).
uint8_t ToWire(cell::Verdict v);
std::optional<cell::Verdict> VerdictFromWire(uint8_t octet);
uint8_t ToWire(cell::TaskStatus s);
std::optional<cell::TaskStatus> TaskStatusFromWire(uint8_t octet);

}  // namespace iplan::services

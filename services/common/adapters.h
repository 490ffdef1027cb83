// Conversions between message types and the plain types of the algorithm
// cores, shared by the services (the only place where both meet).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "iplan/cell/ssm.h"
#include "iplan/cell/status.h"
#include "iplan/collision/joint_mixture.h"
#include "iplan/msg/types.h"

namespace iplan::services {

/// The joint-level mixture of a prediction message (covariances row-major).
collision::JointMixture ToJointMixture(const msg::HumanPrediction& m);

/// Trajectory points as (times in s from header.stamp, positions per point).
void FromTrajectory(const msg::JointTrajectory& m, std::vector<double>* times,
                    std::vector<std::vector<double>>* positions);

/// A trajectory message: `positions` is nq x (n + 1), waypoint i at i * dt
/// after `start`.
msg::JointTrajectory ToTrajectory(const msg::Time& start, const std::vector<std::string>& joint_names,
                                  const Eigen::MatrixXd& positions, double dt);

/// The separation fields of CollisionRisk on the wire: metres, or
/// kWireNoPerson when no person is seen (idl/iplan_msgs.idl).
constexpr double kWireNoPerson = 1e6;
double ToWire(const cell::Separation& s);

/// Status octets by name (CollisionRisk::OK.., TaskOutcome::SUCCEEDED..).
/// FromWire of an octet the IDL does not define returns nullopt (the
/// message boundary refuses those before they reach a service).
uint8_t ToWire(cell::Verdict v);
std::optional<cell::Verdict> VerdictFromWire(uint8_t octet);
uint8_t ToWire(cell::TaskStatus s);
std::optional<cell::TaskStatus> TaskStatusFromWire(uint8_t octet);

}  // namespace iplan::services

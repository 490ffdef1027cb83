// The synthetic person's body: its proportions and how its arm bends. Shared
// by the perception provider that publishes the person (synthetic_person.h)
// and the simulated cell that moves it (services/cell_sim), so both draw the
// same body. Lengths in m.
#pragma once

#include <Eigen/Core>

namespace iplan::perception {

inline constexpr double kUpperArm = 0.30;           ///< m, shoulder to elbow
inline constexpr double kForearm = 0.28;            ///< m, elbow to hand
inline constexpr double kTorsoToNeck = 0.30;        ///< m, torso up to neck
inline constexpr double kNeckToHead = 0.18;         ///< m, neck up to head
inline constexpr double kShoulderBelowNeck = 0.05;  ///< m
/// m, the farthest the hand goes from the shoulder (the arm never locks straight).
inline constexpr double kMaxReach = 0.97 * (kUpperArm + kForearm);

/// Minimum-jerk position profile s(u) = 10u^3 - 15u^4 + 6u^5 for u clamped
/// to [0, 1]: s(0) = 0, s(1) = 1, zero velocity and acceleration at both ends.
double MinJerk(double u);

/// The elbow (same frame as the arguments) of a two-link arm of kUpperArm and
/// kForearm from `shoulder` to `hand`, bending down; a hand beyond reach is
/// taken at full stretch.
Eigen::Vector3d ArmElbow(const Eigen::Vector3d& shoulder, const Eigen::Vector3d& hand);

}  // namespace iplan::perception

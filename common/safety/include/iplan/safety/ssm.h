// ISO/TS 15066 speed and separation monitoring (SSM), as named functions
// with the standard's symbols (ISO/TS 15066:2016, clause 5.5.4):
//
//   S_p = S_h + S_r + S_s + C + Z_d + Z_r
//   S_h = v_h (T_r + T_s)   the person's travel while the robot reacts and stops
//   S_r = v_r T_r           the robot's travel while it reacts
//   S_s                     the robot's stopping distance
//   C                       intrusion distance (a body part reaching past the sensed edge)
//   Z_d, Z_r                position uncertainty of the person (sensing) and of the robot
//
// v_h is the person's speed towards the robot, v_r the robot's speed towards
// the person (m/s); T_r, T_s the robot's reaction and stopping times (s);
// lengths in m. The robot must be stopped while the separation S (surface
// distance between robot and person) is below S_p.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

#include "iplan/core/name_value.h"

namespace iplan::safety {

struct SsmParams {
  bool directed = true;             ///< speeds towards each other per sphere pair; false: fastest joint / sphere, S_s always
  bool measure_human_speed = true;  ///< from the skeleton; else v_h = default_human_speed
  double default_human_speed = 1.6; ///< m/s, ISO value when the speed is not measured
  /// Degraded mode: without a usable prediction the person's intent is
  /// unknown, so v_h is default_human_speed even when the skeleton gives a
  /// measured speed (the robot keeps working, more cautiously).
  bool degrade_without_prediction = true;
  double speed_window = 0.3;        ///< s, displacement window for the measured speed
  double reaction_time = 0.1;       ///< s, T_r
  double stopping_time = 0.3;       ///< s, T_s
  double stopping_distance = 0.15;  ///< m, S_s (at stopping_speed when directed)
  double stopping_speed = 1.0;      ///< m/s, robot speed at which stopping_distance was measured (directed only)
  double intrusion_distance = 0.1;  ///< m, C
  double sensing_uncertainty = 0.05;  ///< m, Z_d
  double robot_uncertainty = 0.02;    ///< m, Z_r
  /// Moving away is not stopped (directed only): a sphere pair inside S_p
  /// whose robot sphere moves away from the human sphere at retreat_speed or
  /// faster is a retreat, not a violation (SsmPairRule). A stop would leave
  /// the robot where the person is heading; its retreat only widens the gap.
  /// <= 0: off (every pair inside S_p stops the robot).
  double retreat_speed = 0.05;        ///< m/s
  /// Speed reduction (directed or not): a robot whose separation would be
  /// below S_p at its trajectory's speed, but not at a lower one, is slowed
  /// down (the executing path time-scaled: SLOW_DOWN with a speed scale)
  /// instead of stopped. The scale keeps d - v_r speed_reduction_time >=
  /// S_p(v_h, scale x v_r) for every pair (what the robot travels while it
  /// slows down); a stop only when even min_speed_scale x v_r leaves d < S_p.
  /// false: every pair inside S_p stops the robot (no speed reduction).
  bool speed_reduction = true;
  double min_speed_scale = 0.1;       ///< below this fraction of its speed the robot is stopped instead, in (0, 1]
  double speed_reduction_time = 0.1;  ///< s, >= 0

  /// Empty when valid, else the reason naming the field.
  std::string Validate() const;

  /// The keys of a configuration's iso_ts_15066 mapping; ranges: Validate().
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(directed, "speeds towards each other per sphere pair; false: fastest joint and sphere, S_s always"));
    a->Visit(IPLAN_NVP(measure_human_speed, "v_h from the skeleton; false: default_human_speed"));
    a->Visit(IPLAN_NVP(default_human_speed, "m/s; v_h when not measured (ISO: 1.6), >= 0"));
    a->Visit(IPLAN_NVP(degrade_without_prediction, "without a usable prediction v_h is default_human_speed"));
    a->Visit(IPLAN_NVP(speed_window, "s; displacement window of the measured speed, > 0"));
    a->Visit(IPLAN_NVP(reaction_time, "s; T_r, >= 0"));
    a->Visit(IPLAN_NVP(stopping_time, "s; T_s, >= 0"));
    a->Visit(IPLAN_NVP(stopping_distance, "m; S_s at stopping_speed, >= 0"));
    a->Visit(IPLAN_NVP(stopping_speed, "m/s; robot speed at which stopping_distance was measured, > 0"));
    a->Visit(IPLAN_NVP(intrusion_distance, "m; C, >= 0"));
    a->Visit(IPLAN_NVP(sensing_uncertainty, "m; Z_d, >= 0"));
    a->Visit(IPLAN_NVP(robot_uncertainty, "m; Z_r, >= 0"));
    a->Visit(IPLAN_NVP(retreat_speed, "m/s; a pair inside S_p whose robot sphere moves away this fast is a retreat, not a stop (<= 0: off; directed only)"));
    a->Visit(IPLAN_NVP(speed_reduction, "slow the robot (time-scale its path) where a lower speed keeps the separation above S_p, instead of stopping it"));
    a->Visit(IPLAN_NVP(min_speed_scale, "below this fraction of its trajectory's speed the robot is stopped instead of slowed, in (0, 1]"));
    a->Visit(IPLAN_NVP(speed_reduction_time, "s; slowing starts v_r x this before S_p is reached (the robot's travel while it slows), >= 0"));
  }
};

/// S_s for a robot moving at v_r towards the person: with `directed`,
/// stopping_distance * min(1, v_r / stopping_speed) (linear in the speed,
/// above the v^2 of a constant deceleration below stopping_speed; a robot at
/// rest or moving away travels nothing towards the person while it stops);
/// otherwise stopping_distance whatever the speed.
double StoppingDistance(const SsmParams& p, double v_r);

/// S_p above for the person's speed v_h and the robot's speed v_r (m/s, >= 0).
double ProtectiveSeparationDistance(const SsmParams& p, double v_h, double v_r);

/// ISO/TS 15066's speed-reduction side: the largest fraction s in [0, 1] of
/// the robot's speed v_r (towards the person, m/s, >= 0) at which a
/// separation d (m) keeps d >= S_p(v_h, s v_r): 1 when d >= S_p(v_h, v_r)
/// already, 0 when even a robot at rest is inside (d < S_p(v_h, 0): only a
/// stop, or moving away, helps).
double SpeedScaleFor(const SsmParams& p, double d, double v_h, double v_r);

/// One robot / human sphere pair as the monitor judges it and the planner
/// predicts it (the same rule for both, so that a plan the planner accepts
/// is one the monitor lets run).
struct SsmPair {
  double separation = 0;  ///< m, surface distance d
  double v_h = 0;         ///< m/s, the human sphere's speed towards the robot sphere (>= 0)
  double v_r = 0;         ///< m/s, the robot sphere's speed towards the human sphere (>= 0)
  double protective_separation = 0;  ///< m, S_p(v_h, v_r)
  double margin = 0;      ///< m, d - S_p; < 0 is inside S_p
  bool retreating = false;  ///< inside S_p, but the robot sphere moves away at retreat_speed or faster
  /// Speed reduction (SsmParams::speed_reduction): the fraction of the
  /// robot sphere's speed at which d - v_r speed_reduction_time >= S_p, and
  /// at which d >= S_p (SpeedScaleFor); 1 for a retreat.
  double slow_scale = 1.0;
  double stop_scale = 1.0;
  /// Inside S_p and not retreating: the robot must not go on at its speed
  /// (it is slowed down, or stopped when even min_speed_scale is too fast).
  bool violates() const { return margin < 0 && !retreating; }
};

/// The pair rule with directed speeds: `delta` is the robot sphere's centre
/// minus the human sphere's (m, W), `radii` their sum (m), `v_human` and
/// `v_robot` the spheres' velocities (m/s, W). v_h and v_r are the
/// components towards each other (clamped at 0); the robot sphere retreats
/// when its component away from the person is at least retreat_speed
/// (> 0). Coincident centres give S_p > 0 > d, never a retreat.
SsmPair SsmPairRule(const SsmParams& p, const Eigen::Vector3d& delta, double radii, const Eigen::Vector3d& v_human,
                    const Eigen::Vector3d& v_robot);

/// A robot-person separation (m): nullopt when no person is seen. Negative
/// values are penetration depths.
using Separation = std::optional<double>;

}  // namespace iplan::safety

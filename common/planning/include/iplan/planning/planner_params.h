// Parameters of the ITOMP-style trajectory optimiser (METHOD.md section 5).
// SI units: s, m, rad. Loaded strictly from YAML (config/planner.yaml).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "iplan/safety/ssm.h"
#include "iplan/core/name_value.h"

namespace iplan::planning {

/// Weights of the cost terms (dimensionless multipliers of the terms defined
/// in planner.h; all >= 0).
struct CostWeights {
  double smoothness = 1.0;   ///< x sum_i dt ||a_i||^2 (a in rad/s^2)
  double obstacle = 2000.0;  ///< x sum max(0, margin - d)^2 (d in m), per sphere/object
  double dynamic = 1e4;      ///< x sum_i max(0, P_i - threshold)^2
  double goal = 0.5;         ///< x sum_i dt ||q_i - q_goal||^2 (rad^2 s)
  double limits = 50.0;      ///< x squared velocity/acceleration limit excess (normalised)
  double separation = 2000.0; ///< x sum max(0, human_separation - d)^2 (d in m), per robot/human sphere pair
  double ssm = 2000.0;        ///< x sum p(c) max(0, ssm_activation - (d - S_p))^2 (m), per violating sphere pair (predict_ssm)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(smoothness, "x sum_i dt ||a_i||^2 (a in rad/s^2); > 0, it is the metric"));
    a->Visit(IPLAN_NVP(obstacle, "x sum max(0, obstacle_margin - d)^2 (d in m), per sphere/object; >= 0"));
    a->Visit(IPLAN_NVP(dynamic, "x sum_i max(0, P_i - threshold)^2; >= 0"));
    a->Visit(IPLAN_NVP(goal, "x sum_i dt ||q_i - q_goal||^2 (rad^2 s); >= 0"));
    a->Visit(IPLAN_NVP(limits, "x squared velocity/acceleration limit excess (normalised); >= 0"));
    a->Visit(IPLAN_NVP(separation, "x sum max(0, human_separation - d)^2 (d in m), per robot/human sphere pair; >= 0"));
    a->Visit(IPLAN_NVP(ssm, "x sum p(c) max(0, ssm_activation - (d - S_p))^2 (m), per sphere pair (predict_ssm); >= 0"));
  }
};

struct PlannerParams {
  /// Waypoint spacing dt (s), > 0.
  double dt = 0.1;
  /// Planning horizon (s): n = round(horizon / dt) intervals, n + 1 waypoints.
  double horizon = 3.0;
  /// Safety level delta_CL in (0, 1): a waypoint is safe when its bound
  /// P_i < 1 - delta_CL (METHOD 4).
  double delta_cl = 0.95;
  /// The dynamic cost starts at dynamic_activation * (1 - delta_CL) (in (0, 1]),
  /// a margin below the threshold so that the optimiser keeps away from it.
  double dynamic_activation = 0.5;
  /// Number of parallel optimisers N (>= 1) and worker threads (0 = N,
  /// capped at N). The result does not depend on the thread count.
  int num_optimizers = 8;
  int num_threads = 0;
  /// Seed of optimiser o's generator: derived from (seed, o) only.
  std::uint64_t seed = 1;
  /// Gradient iterations per optimiser and attempt (>= 1).
  int max_iterations = 60;
  /// An optimiser stops early when feasible and the relative cost decrease of
  /// an iteration is below this (>= 0).
  double convergence_tolerance = 1e-4;
  /// Deterministic early stop (>= 0): with K > 0 the optimisers advance in
  /// rounds of K iterations and all stop after the first round in which one
  /// of them is feasible and safe (the winner is then chosen as usual among
  /// the feasible ones); 0 = every optimiser runs to convergence. Rounds are
  /// decided on the optimisers' states only, so results do not depend on the
  /// thread count. Meant for replanning (a good warm start is usually feasible
  /// at once); it trades final cost for time.
  int early_stop_interval = 0;
  /// With a time budget (PlanningRequest::time_budget), the fraction of it
  /// kept for the work after the optimisers stop (the last feasibility
  /// checks, exact bounds, the failure report), in [0, 0.9): the optimisers
  /// stop at (1 - budget_reserve) x the budget, so that Plan returns within
  /// the budget rather than one iteration and the checks after it.
  double budget_reserve = 0.15;
  /// Step size of the covariant update x -= step * H^-1 grad, in (0, 1].
  double step_size = 0.5;
  /// Std-dev (rad) of the random via-point offset of optimisers 1..N-1.
  double initial_perturbation = 0.5;
  /// Static clearance: hinge margin of the obstacle cost (m, >= 0) and the
  /// clearance a feasible trajectory must keep (m) at collision_check_substeps
  /// linearly interpolated points per interval (>= 1); from a start closer
  /// than min_clearance, no closer than the start (it may only move out).
  double obstacle_margin = 0.05;
  double min_clearance = 0.0;
  int collision_check_substeps = 10;
  /// Pairs (robot link, scene object) never checked, e.g. the base on the
  /// table; the link "<base>" stands for the robot's first two links with
  /// collision spheres (the base on its mount and the first moving link), so
  /// that one planner file serves any arm.
  std::vector<std::pair<std::string, std::string>> allowed_collisions = {
      {"panda_link0", "table"}, {"panda_link1", "table"}};
  /// Waits: duration of one inserted wait (s, multiple of dt after rounding,
  /// >= dt) and the maximum number of waits before giving up (>= 0).
  double wait_duration = 0.5;
  int max_waits = 6;
  /// Keep-out from the predicted person (m, >= 0; 0 = off): the separation
  /// cost pushes every free waypoint's robot spheres this far from the
  /// predicted human spheres (surface to surface, from each action's mean
  /// at that waypoint's time, weighted by the action's probability; actions
  /// below 30 % are ignored, so an unlikely action never blocks a goal). Set it near the ISO/TS
  /// 15066 protective separation distance so that plans go around the
  /// person, or hold off, before the separation monitor has to stop the
  /// robot. A soft cost: it shapes plans but never makes one infeasible.
  double human_separation = 0.0;
  /// Predicting the separation monitor (ISO/TS 15066 SSM): with
  /// predict_ssm, every free waypoint within ssm_horizon of waypoint 0 is
  /// judged by the monitor's own pair rule (safety::SsmPairRule, with `ssm`,
  /// the monitor's parameters) against the predicted person: each action at
  /// its mean, moving as its mean moves between prediction steps, and the
  /// robot sphere moving as the plan moves it to the next waypoint. A
  /// waypoint is unsafe (the monitor would stop the plan there) when the
  /// actions under which some pair is inside S_p + ssm_margin without
  /// retreating have ssm_stop_probability or more; the ssm cost, weighted
  /// by each action's probability, starts at ssm_activation (>= ssm_margin)
  /// so that plans keep clear of that, slow down near the person and, when
  /// the person comes towards the robot, get out of their way.
  bool predict_ssm = false;
  /// With predict_ssm and the monitor's speed reduction
  /// (ssm.speed_reduction): the rule is the monitor's stop, not its slowing.
  /// Each pair is judged with the robot sphere at ssm.min_speed_scale of the
  /// plan's speed, the slowest the monitor slows the robot to before it
  /// stops it, so a plan the monitor would only slow down stays feasible
  /// and costs nothing. false: the plan's own speed (the monitor's slowing
  /// counts as a stop).
  bool ssm_predicts_slowing = false;
  /// A replan towards the goal its warm start already ends at keeps the
  /// warm start's arrival (its length, at least num_frozen + 3 waypoints)
  /// instead of planning a whole horizon again. false: every plan arrives a
  /// horizon after its start, so each replan moves the arrival later and the
  /// last part of a motion decays (about 1 s for the last 0.2 rad of the
  /// Panda with a 1.5 s horizon).
  bool keep_arrival = false;
  /// A plan towards a new goal (not one its warm start already ends at)
  /// takes the time its distance needs, max(min_motion_time, 1.5 t_min /
  /// motion_speed_fraction) with t_min = max_j |q_goal,j - q_j| / vmax_j, at
  /// most the horizon: the motion's peak joint speed is about this fraction
  /// of its limit. In [0, 1]; 0: every new goal gets the whole horizon.
  double motion_speed_fraction = 0.0;
  double min_motion_time = 1.0;  ///< s, >= 0; see motion_speed_fraction
  safety::SsmParams ssm;
  double ssm_margin = 0.03;          ///< m, >= 0
  double ssm_activation = 0.05;      ///< m, >= ssm_margin
  double ssm_horizon = 1.0;          ///< s, > 0
  double ssm_stop_probability = 0.5;  ///< in (0, 1]
  /// Joint limits are shrunk by this margin (rad) for the optimiser (>= 0).
  double position_margin = 1e-3;
  /// Velocity/acceleration limits are scaled by this factor in (0, 1] for the
  /// optimiser's penalty (the feasibility check uses the full limits).
  double limit_scale = 0.9;
  /// End effector for pose goals: link name ("" = the robot file's
  /// tool_link, else its last link) and offset p_LE (m) in that link.
  std::string end_effector_link = "panda_link8";
  std::array<double, 3> end_effector_offset = {0.0, 0.0, 0.0};
  /// Inverse kinematics (damped least squares): iterations, damping (m), and
  /// tolerances on position (m) and orientation (rad); restarts from random
  /// seeds (>= 0).
  int ik_max_iterations = 200;
  double ik_damping = 0.05;
  double ik_position_tolerance = 1e-4;
  double ik_orientation_tolerance = 1e-3;
  int ik_restarts = 8;
  CostWeights weights;

  /// The YAML keys (config/planner.yaml), one line of doc each; the ranges
  /// are Validate()'s.
  template <class Archive>
  void Serialize(Archive* a);

  /// Empty string when valid, else the reason naming the field and value.
  std::string Validate() const;
};

template <class Archive>
void PlannerParams::Serialize(Archive* a) {
  a->Visit(IPLAN_NVP(dt, "s; waypoint spacing, > 0"));
  a->Visit(IPLAN_NVP(horizon, "s; n = round(horizon / dt) intervals, >= 2 dt"));
  a->Visit(IPLAN_NVP(delta_cl, "safety level in (0, 1): a waypoint is safe when its bound P_i < 1 - delta_cl"));
  a->Visit(IPLAN_NVP(dynamic_activation, "the dynamic cost starts at this x (1 - delta_cl), in (0, 1]"));
  a->Visit(IPLAN_NVP(num_optimizers, "parallel optimisers N, >= 1"));
  a->Visit(IPLAN_NVP(num_threads, "worker threads, >= 0 (0 = N, capped at N); results do not depend on it"));
  a->Visit(IPLAN_NVP(seed, "seed of the optimisers' generators (optimiser o: from seed and o only)"));
  a->Visit(IPLAN_NVP(max_iterations, "gradient iterations per optimiser and attempt, >= 1"));
  a->Visit(IPLAN_NVP(convergence_tolerance, "stop when feasible and the relative cost decrease is below this, >= 0"));
  a->Visit(IPLAN_NVP(early_stop_interval, "rounds of K iterations, all stop after one is feasible and safe; 0 = off"));
  a->Visit(IPLAN_NVP(budget_reserve, "fraction of a time budget kept for the checks after the optimisers stop, in [0, 0.9)"));
  a->Visit(IPLAN_NVP(step_size, "step of the covariant update, in (0, 1]"));
  a->Visit(IPLAN_NVP(initial_perturbation, "rad; std-dev of the via-point offset of optimisers 1..N-1, >= 0"));
  a->Visit(IPLAN_NVP(obstacle_margin, "m; hinge margin of the obstacle cost, >= 0"));
  a->Visit(IPLAN_NVP(min_clearance, "m; static clearance a feasible trajectory keeps, <= obstacle_margin"));
  a->Visit(IPLAN_NVP(collision_check_substeps, "interpolated collision checks per interval, >= 1"));
  a->Visit(IPLAN_NVP(allowed_collisions, "[robot link, scene object] pairs never checked; link <base>: the robot's first two links with spheres (its base on the mount)"));
  a->Visit(IPLAN_NVP(wait_duration, "s; one inserted wait, >= dt"));
  a->Visit(IPLAN_NVP(max_waits, "waits inserted before giving up, >= 0"));
  a->Visit(IPLAN_NVP(human_separation, "m; soft keep-out from the predicted person, >= 0 (0 = off)"));
  a->Visit(IPLAN_NVP(predict_ssm, "judge plans by the separation monitor's rule against the predicted person"));
  a->Visit(IPLAN_NVP(ssm_predicts_slowing, "with the monitor's speed_reduction: judge pairs at min_speed_scale x the plan's speed (the monitor's stop, not its slowing)"));
  a->Visit(IPLAN_NVP(keep_arrival, "a replan towards its warm start's goal keeps that arrival (at least num_frozen + 3 waypoints) instead of a whole horizon"));
  a->Visit(IPLAN_NVP(motion_speed_fraction, "a plan to a new goal takes max(min_motion_time, 1.5 t_min / this) (t_min: largest joint distance over its speed limit), at most the horizon; in [0, 1], 0: the whole horizon"));
  a->Visit(IPLAN_NVP(min_motion_time, "s; the shortest plan to a new goal with motion_speed_fraction, >= 0"));
  a->Visit(core::MakeNameValue("iso_ts_15066", &ssm, "the monitor's ISO/TS 15066 parameters (trajopt: from the cell's safety file)"));
  a->Visit(IPLAN_NVP(ssm_margin, "m; a safe plan keeps d - S_p >= this at every free waypoint within ssm_horizon, >= 0"));
  a->Visit(IPLAN_NVP(ssm_activation, "m; the ssm cost starts below this margin, >= ssm_margin"));
  a->Visit(IPLAN_NVP(ssm_horizon, "s; waypoints judged by the monitor's rule, > 0"));
  a->Visit(IPLAN_NVP(ssm_stop_probability, "a waypoint is unsafe when the actions the monitor would stop have this probability, in (0, 1]"));
  a->Visit(IPLAN_NVP(position_margin, "rad; joint limits shrunk by this for the optimiser, >= 0"));
  a->Visit(IPLAN_NVP(limit_scale, "velocity/acceleration limits x this in the penalty, in (0, 1]"));
  a->Visit(IPLAN_NVP(end_effector_link, "link of pose goals; \"\" = the robot file's tool_link, else its last link"));
  a->Visit(IPLAN_NVP(end_effector_offset, "m; [x, y, z] of the end effector in that link, finite"));
  a->Visit(IPLAN_NVP(ik_max_iterations, "inverse kinematics iterations, >= 1"));
  a->Visit(IPLAN_NVP(ik_damping, "m; damping of the damped least squares, > 0"));
  a->Visit(IPLAN_NVP(ik_position_tolerance, "m; > 0"));
  a->Visit(IPLAN_NVP(ik_orientation_tolerance, "rad; > 0"));
  a->Visit(IPLAN_NVP(ik_restarts, "restarts from random seeds, >= 0"));
  a->Visit(IPLAN_NVP(weights, "cost weights (dimensionless)"));
}

/// Loads PlannerParams from YAML (core::LoadParamsFile): keys as in
/// Serialize, weights under `weights:`, allowed_collisions as a list of
/// [link, object] pairs; `overrides` ({"weights.goal", "2"}, from --set) are
/// applied first. Missing keys keep their defaults; an empty file is all
/// defaults; unknown or mistyped keys are errors.
/// @throws std::runtime_error (core::ConfigError) naming the file, key and
///         value (also when the result fails Validate()). Thread-safe; allocates.
PlannerParams LoadPlannerParams(const std::string& path, const core::Overrides& overrides = {});

}  // namespace iplan::planning

#include "iplan/planning/planner_params.h"

#include "iplan/core/params.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace iplan::planning {
namespace {

std::string Num(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

}  // namespace

std::string PlannerParams::Validate() const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  auto nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
  if (!positive(dt)) return "dt must be > 0, got " + Num(dt);
  if (!positive(horizon) || horizon < 2.0 * dt)
    return "horizon must be >= 2 dt, got " + Num(horizon) + " (dt " + Num(dt) + ")";
  if (!(delta_cl > 0.0 && delta_cl < 1.0)) return "delta_cl must be in (0, 1), got " + Num(delta_cl);
  if (!(dynamic_activation > 0.0 && dynamic_activation <= 1.0))
    return "dynamic_activation must be in (0, 1], got " + Num(dynamic_activation);
  if (num_optimizers < 1) return "num_optimizers must be >= 1, got " + std::to_string(num_optimizers);
  if (num_threads < 0) return "num_threads must be >= 0, got " + std::to_string(num_threads);
  if (max_iterations < 1) return "max_iterations must be >= 1, got " + std::to_string(max_iterations);
  if (early_stop_interval < 0)
    return "early_stop_interval must be >= 0, got " + std::to_string(early_stop_interval);
  if (!(budget_reserve >= 0.0 && budget_reserve < 0.9))
    return "budget_reserve must be in [0, 0.9), got " + Num(budget_reserve);
  if (!nonneg(convergence_tolerance))
    return "convergence_tolerance must be >= 0, got " + Num(convergence_tolerance);
  if (!(step_size > 0.0 && step_size <= 1.0)) return "step_size must be in (0, 1], got " + Num(step_size);
  if (!nonneg(initial_perturbation))
    return "initial_perturbation must be >= 0, got " + Num(initial_perturbation);
  if (!nonneg(obstacle_margin)) return "obstacle_margin must be >= 0, got " + Num(obstacle_margin);
  if (!std::isfinite(min_clearance)) return "min_clearance must be finite, got " + Num(min_clearance);
  if (min_clearance > obstacle_margin)
    return "min_clearance (" + Num(min_clearance) + ") must be <= obstacle_margin (" +
           Num(obstacle_margin) + ")";
  if (collision_check_substeps < 1)
    return "collision_check_substeps must be >= 1, got " + std::to_string(collision_check_substeps);
  if (!(std::isfinite(wait_duration) && wait_duration >= dt))
    return "wait_duration must be >= dt, got " + Num(wait_duration);
  if (max_waits < 0) return "max_waits must be >= 0, got " + std::to_string(max_waits);
  if (!nonneg(human_separation)) return "human_separation must be >= 0, got " + Num(human_separation);
  if (!nonneg(ssm_margin)) return "ssm_margin must be >= 0, got " + Num(ssm_margin);
  if (!(std::isfinite(ssm_activation) && ssm_activation >= ssm_margin))
    return "ssm_activation must be >= ssm_margin (" + Num(ssm_margin) + "), got " + Num(ssm_activation);
  if (!(motion_speed_fraction >= 0.0 && motion_speed_fraction <= 1.0))
    return "motion_speed_fraction must be in [0, 1], got " + Num(motion_speed_fraction);
  if (!nonneg(min_motion_time)) return "min_motion_time must be >= 0, got " + Num(min_motion_time);
  if (!positive(ssm_horizon)) return "ssm_horizon must be > 0, got " + Num(ssm_horizon);
  if (!(ssm_stop_probability > 0.0 && ssm_stop_probability <= 1.0))
    return "ssm_stop_probability must be in (0, 1], got " + Num(ssm_stop_probability);
  if (std::string why = ssm.Validate(); !why.empty()) return "iso_ts_15066: " + why;
  if (!nonneg(position_margin)) return "position_margin must be >= 0, got " + Num(position_margin);
  if (!(limit_scale > 0.0 && limit_scale <= 1.0))
    return "limit_scale must be in (0, 1], got " + Num(limit_scale);
  for (double v : end_effector_offset)
    if (!std::isfinite(v)) return "end_effector_offset must be finite, got " + Num(v);
  if (ik_max_iterations < 1)
    return "ik_max_iterations must be >= 1, got " + std::to_string(ik_max_iterations);
  if (!positive(ik_damping)) return "ik_damping must be > 0, got " + Num(ik_damping);
  if (!positive(ik_position_tolerance))
    return "ik_position_tolerance must be > 0, got " + Num(ik_position_tolerance);
  if (!positive(ik_orientation_tolerance))
    return "ik_orientation_tolerance must be > 0, got " + Num(ik_orientation_tolerance);
  if (ik_restarts < 0) return "ik_restarts must be >= 0, got " + std::to_string(ik_restarts);
  const std::pair<const char*, double> w[] = {{"smoothness", weights.smoothness},
                                              {"obstacle", weights.obstacle},
                                              {"dynamic", weights.dynamic},
                                              {"goal", weights.goal},
                                              {"limits", weights.limits},
                                              {"separation", weights.separation},
                                              {"ssm", weights.ssm}};
  for (const auto& [name, v] : w)
    if (!nonneg(v)) return std::string("weights.") + name + " must be >= 0, got " + Num(v);
  if (!(weights.smoothness > 0.0)) return "weights.smoothness must be > 0 (it is the metric)";
  return "";
}

PlannerParams LoadPlannerParams(const std::string& path, const core::Overrides& overrides) {
  return core::LoadParamsFile<PlannerParams>(path, overrides);
}

}  // namespace iplan::planning

#include "iplan/planning/planner_params.h"

#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "iplan/core/yaml.h"

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
  if (!nonneg(position_margin)) return "position_margin must be >= 0, got " + Num(position_margin);
  if (!(limit_scale > 0.0 && limit_scale <= 1.0))
    return "limit_scale must be in (0, 1], got " + Num(limit_scale);
  if (end_effector_link.empty()) return "end_effector_link must not be empty";
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
                                              {"separation", weights.separation}};
  for (const auto& [name, v] : w)
    if (!nonneg(v)) return std::string("weights.") + name + " must be >= 0, got " + Num(v);
  if (!(weights.smoothness > 0.0)) return "weights.smoothness must be > 0 (it is the metric)";
  return "";
}

namespace {

template <typename T>
T Read(const YAML::Node& node, const std::string& key, const std::string& path) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(path + ": key '" + key + "' has a value of the wrong type: '" +
                             YAML::Dump(node) + "'");
  }
}

}  // namespace

PlannerParams LoadPlannerParams(const std::string& path) {
  YAML::Node root;
  try {
    root = core::LoadYamlFile(path);  // a key twice is an error
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": cannot read planner params: " + e.what());
  }
  PlannerParams p;
  if (!root || root.IsNull()) return p;
  if (!root.IsMap()) throw std::runtime_error(path + ": planner params must be a map");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    const YAML::Node& v = kv.second;
    auto rd = [&](double* out) { *out = Read<double>(v, key, path); };
    auto ri = [&](int* out) { *out = Read<int>(v, key, path); };
    if (key == "dt") rd(&p.dt);
    else if (key == "horizon") rd(&p.horizon);
    else if (key == "delta_cl") rd(&p.delta_cl);
    else if (key == "dynamic_activation") rd(&p.dynamic_activation);
    else if (key == "num_optimizers") ri(&p.num_optimizers);
    else if (key == "num_threads") ri(&p.num_threads);
    else if (key == "seed") p.seed = Read<std::uint64_t>(v, key, path);
    else if (key == "max_iterations") ri(&p.max_iterations);
    else if (key == "convergence_tolerance") rd(&p.convergence_tolerance);
    else if (key == "early_stop_interval") ri(&p.early_stop_interval);
    else if (key == "step_size") rd(&p.step_size);
    else if (key == "initial_perturbation") rd(&p.initial_perturbation);
    else if (key == "obstacle_margin") rd(&p.obstacle_margin);
    else if (key == "min_clearance") rd(&p.min_clearance);
    else if (key == "collision_check_substeps") ri(&p.collision_check_substeps);
    else if (key == "wait_duration") rd(&p.wait_duration);
    else if (key == "max_waits") ri(&p.max_waits);
    else if (key == "human_separation") rd(&p.human_separation);
    else if (key == "position_margin") rd(&p.position_margin);
    else if (key == "limit_scale") rd(&p.limit_scale);
    else if (key == "end_effector_link") p.end_effector_link = Read<std::string>(v, key, path);
    else if (key == "end_effector_offset") {
      const auto xyz = Read<std::vector<double>>(v, key, path);
      if (xyz.size() != 3)
        throw std::runtime_error(path + ": end_effector_offset needs 3 numbers, got " +
                                 std::to_string(xyz.size()));
      p.end_effector_offset = {xyz[0], xyz[1], xyz[2]};
    } else if (key == "ik_max_iterations") ri(&p.ik_max_iterations);
    else if (key == "ik_damping") rd(&p.ik_damping);
    else if (key == "ik_position_tolerance") rd(&p.ik_position_tolerance);
    else if (key == "ik_orientation_tolerance") rd(&p.ik_orientation_tolerance);
    else if (key == "ik_restarts") ri(&p.ik_restarts);
    else if (key == "allowed_collisions") {
      p.allowed_collisions.clear();
      const auto pairs = Read<std::vector<std::vector<std::string>>>(v, key, path);
      for (const auto& pr : pairs) {
        if (pr.size() != 2)
          throw std::runtime_error(path + ": allowed_collisions entries must be [link, object]");
        p.allowed_collisions.emplace_back(pr[0], pr[1]);
      }
    } else if (key == "weights") {
      if (!v.IsMap()) throw std::runtime_error(path + ": 'weights' must be a map");
      for (const auto& w : v) {
        const std::string wk = w.first.as<std::string>();
        const double wv = Read<double>(w.second, "weights." + wk, path);
        if (wk == "smoothness") p.weights.smoothness = wv;
        else if (wk == "obstacle") p.weights.obstacle = wv;
        else if (wk == "dynamic") p.weights.dynamic = wv;
        else if (wk == "goal") p.weights.goal = wv;
        else if (wk == "limits") p.weights.limits = wv;
        else if (wk == "separation") p.weights.separation = wv;
        else throw std::runtime_error(path + ": unknown key 'weights." + wk + "'");
      }
    } else {
      throw std::runtime_error(path + ": unknown key '" + key + "'");
    }
  }
  if (const std::string why = p.Validate(); !why.empty())
    throw std::runtime_error(path + ": " + why);
  return p;
}

}  // namespace iplan::planning

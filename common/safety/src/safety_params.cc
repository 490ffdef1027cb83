#include "iplan/safety/safety_params.h"

#include "iplan/core/params.h"

namespace iplan::safety {
namespace {

std::string Text(double v) { return core::ParamText(v); }
std::string Text(bool v) { return core::ParamText(v); }

}  // namespace

std::string SafetyParams::Validate() const {
  if (!(delta_cl > 0 && delta_cl < 1)) return "delta_cl must be in (0, 1), got " + Text(delta_cl);
  if (std::string why = ssm.Validate(); !why.empty()) return "iso_ts_15066: " + why;
  if (!(stop_horizon >= 0)) return "stop_horizon must be >= 0, got " + Text(stop_horizon);
  if (!(bound_retreat_gain >= 0 && bound_retreat_gain <= 1))
    return "bound_retreat_gain must be in [0, 1], got " + Text(bound_retreat_gain);
  return "";
}

SafetyParams LoadSafetyParams(const std::string& path) {
  SafetyParams p = core::LoadParamsFile<SafetyParams>(path, {}, core::ConfigSection::EmptyFile::kError);
  if (std::string why = p.Validate(); !why.empty()) throw core::ConfigError(path + ": " + why);
  return p;
}

std::string SsmDifference(const SsmParams& a, const SsmParams& b) {
  const std::pair<const char*, std::pair<double, double>> numbers[] = {
      {"default_human_speed", {a.default_human_speed, b.default_human_speed}},
      {"speed_window", {a.speed_window, b.speed_window}},
      {"reaction_time", {a.reaction_time, b.reaction_time}},
      {"stopping_time", {a.stopping_time, b.stopping_time}},
      {"stopping_distance", {a.stopping_distance, b.stopping_distance}},
      {"stopping_speed", {a.stopping_speed, b.stopping_speed}},
      {"intrusion_distance", {a.intrusion_distance, b.intrusion_distance}},
      {"sensing_uncertainty", {a.sensing_uncertainty, b.sensing_uncertainty}},
      {"robot_uncertainty", {a.robot_uncertainty, b.robot_uncertainty}},
      {"retreat_speed", {a.retreat_speed, b.retreat_speed}}};
  const std::pair<const char*, std::pair<bool, bool>> flags[] = {
      {"directed", {a.directed, b.directed}},
      {"measure_human_speed", {a.measure_human_speed, b.measure_human_speed}},
      {"degrade_without_prediction", {a.degrade_without_prediction, b.degrade_without_prediction}}};
  for (const auto& [key, v] : flags)
    if (v.first != v.second) return std::string("iso_ts_15066.") + key + " " + Text(v.first) + " vs " + Text(v.second);
  for (const auto& [key, v] : numbers)
    if (v.first != v.second) return std::string("iso_ts_15066.") + key + " " + Text(v.first) + " vs " + Text(v.second);
  return "";
}

}  // namespace iplan::safety

#include "perception_settings.h"

#include <cmath>

namespace iplan::perception {
namespace {

Eigen::Vector3d Vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

std::string Num(double v) { return core::ParamText(v); }

// "" or `prefix` + why.
std::string In(const std::string& prefix, const std::string& why) { return why.empty() ? why : prefix + why; }

}  // namespace

std::string ActionSettings::Validate() const {
  if (motion != "reach" && motion != "work" && motion != "rest") {
    return "motion must be reach, work or rest, got '" + motion + "'";
  }
  if (hand != "left" && hand != "right") return "hand must be left or right, got '" + hand + "'";
  if (motion != "rest" && !target) return "target is required for motion " + motion;
  if (!(period > 0)) return "period must be > 0, got " + Num(period);
  if (!(amplitude >= 0)) return "amplitude must be >= 0, got " + Num(amplitude);
  return "";
}

ActionMotion ActionSettings::ToMotion(const std::string& name) const {
  ActionMotion m;
  m.name = name;
  m.kind = motion == "reach" ? MotionKind::kReach : motion == "work" ? MotionKind::kWork : MotionKind::kRest;
  m.right_hand = hand == "right";
  if (target) m.target_W = Vec(*target);
  m.period = period;
  m.amplitude = amplitude;
  return m;
}

SyntheticPersonParams SyntheticSettings::Person() const {
  SyntheticPersonParams p;
  p.torso_W = Vec(torso);
  p.facing_yaw = facing_yaw;
  p.noise_stddev = noise_stddev;
  p.variation = variation;
  p.transition = transition;
  p.rest_left_P = Vec(rest_hand);
  p.seed = seed;
  p.loop = Start() == ScriptStart::kLoop;
  p.actions.clear();
  for (const auto& [name, a] : actions) p.actions.push_back(a.ToMotion(name));
  for (std::size_t i = 0; i < script.size() && i < durations.size(); ++i) p.script.push_back({script[i], durations[i]});
  return p;
}

std::vector<SyntheticPersonParams> SyntheticSettings::MorePeople() const {
  const SyntheticPersonParams first = Person();
  std::vector<SyntheticPersonParams> out;
  for (std::size_t i = 0; i < more_people.size(); ++i) {
    const MorePersonSettings& m = more_people[i];
    SyntheticPersonParams p = first;
    if (m.torso) p.torso_W = Vec(*m.torso);
    if (m.facing_yaw) p.facing_yaw = *m.facing_yaw;
    p.seed = m.seed ? *m.seed : first.seed + i + 1;
    out.push_back(p);
  }
  return out;
}

std::string SyntheticSettings::Validate() const {
  if (start != "loop" && start != "episodes") return "start must be loop or episodes, got '" + start + "'";
  if (actions.empty()) return "actions: at least one action is needed";
  for (const auto& [name, a] : actions) {
    if (std::string why = a.Validate(); !why.empty()) return "actions." + name + "." + why;
  }
  if (script.size() != durations.size()) {
    return "durations must have one duration (s) per script step (" + std::to_string(script.size()) + "), got " +
           std::to_string(durations.size());
  }
  for (std::size_t i = 0; i < more_people.size(); ++i) {
    if (const auto& t = more_people[i].torso; t && !Vec(*t).allFinite()) {
      return "more_people[" + std::to_string(i) + "].torso must be finite";
    }
  }
  return Person().Validate();  // the core's ranges (noise, variation, script steps naming actions, ...)
}

std::string ReplayTransformSettings::Validate() const {
  if (matrix) {
    if (translation || yaw) return "matrix: give either matrix or translation/yaw, not both";
    Eigen::Isometry3d X;
    return In("matrix: ", TransformFromMatrix(*matrix, &X));
  }
  if (translation && !Vec(*translation).allFinite()) return "translation must be finite";
  if (yaw && !std::isfinite(*yaw)) return "yaw must be finite";
  return "";
}

Eigen::Isometry3d ReplayTransformSettings::Pose() const {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  if (matrix) {
    TransformFromMatrix(*matrix, &X);
    return X;
  }
  return TransformFromTranslationYaw(translation ? Vec(*translation) : Eigen::Vector3d::Zero(), yaw.value_or(0.0));
}

std::string ReplaySettings::Validate() const {
  if (std::string why = transform.Validate(); !why.empty()) return "transform." + why;
  return ToParams(file.empty() ? std::string("(none)") : file).Validate();  // ranges; the file is checked on loading
}

SkeletonReplayParams ReplaySettings::ToParams(const std::string& resolved_file) const {
  SkeletonReplayParams p;
  p.file = resolved_file;
  p.sequences = sequences;
  p.subjects = subjects;
  p.loop = loop;
  p.rate = rate;
  p.pause = pause;
  p.start_delay = start_delay;
  p.joint_map = joint_map;
  if (transform.Validate().empty()) p.X_WS = transform.Pose();
  return p;
}

std::string SimulatedDepthSettings::Validate() const {
  if (std::string why = camera.Validate(); !why.empty()) return why;
  if (std::string why = intrinsics.Validate(); !why.empty()) return "intrinsics." + why;
  if (std::string why = noise.Validate(); !why.empty()) return "noise." + why;
  if (!(min_range >= 0)) return "min_range must be >= 0, got " + Num(min_range);
  if (!(max_range > min_range)) return "max_range must be > min_range, got " + Num(max_range);
  if (!(added_after >= 0)) return "added_after must be >= 0, got " + Num(added_after);
  if (!(human_after >= 0)) return "human_after must be >= 0, got " + Num(human_after);
  return "";
}

DepthCameraParams SimulatedDepthSettings::Camera() const {
  DepthCameraParams p;
  p.intrinsics = intrinsics;
  p.X_WS = camera.Pose();
  p.noise = noise;
  p.add_noise = add_noise;
  p.min_range = min_range;
  p.max_range = max_range;
  p.seed = seed;
  return p;
}

std::string DepthSettings::Validate() const {
  if (provider != "none" && provider != "simulated" && provider != "pcd") {
    return "provider must be none, simulated or pcd, got '" + provider + "'";
  }
  if (!(rate_hz >= 0.1 && rate_hz <= 120)) return "rate_hz must be in [0.1, 120], got " + Num(rate_hz);
  if (transport != "points" && transport != "image") return "transport must be points or image, got '" + transport + "'";
  if (provider == "pcd" && transport == "image") {
    return "transport image needs provider simulated: a PCD file carries no camera intrinsics to publish with "
           "its images";
  }
  if (provider == "pcd" && pcd.path.empty()) return "pcd.path is required with provider pcd (a .pcd file or a folder of them)";
  // Both providers' keys are checked always, so that switching keeps the file valid.
  return In("simulated.", simulated.Validate());
}

std::string PerceptionSettings::Validate() const {
  if (provider != "synthetic" && provider != "replay") {
    return "provider must be synthetic or replay, got '" + provider + "'";
  }
  if (!(rate_hz >= 0.5 && rate_hz <= 1000)) return "rate_hz must be in [0.5, 1000], got " + Num(rate_hz);
  if (frame_id.empty()) return "frame_id must not be empty";
  if (std::string why = synthetic.Validate(); !why.empty()) return "synthetic." + why;
  if (provider == "replay" && replay.file.empty()) return "replay.file is required with provider replay";
  if (std::string why = replay.Validate(); !why.empty()) return "replay." + why;
  return In("depth.", depth.Validate());
}

}  // namespace iplan::perception

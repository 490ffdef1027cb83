#include "synthetic_config.h"

namespace iplan::perception {
namespace {

std::string Three(const std::vector<double>& v) {
  return v.size() == 3 ? std::string() : "must have 3 numbers (x, y, z in m)";
}

// The further persons: the first person's parameters with their own pose and seed.
std::vector<SyntheticPersonParams> ReadMorePeople(framework::ConfigSection& syn, const SyntheticPersonParams& first) {
  std::vector<SyntheticPersonParams> out;
  if (!syn.Has("more_people")) return out;
  std::vector<framework::ConfigSection> people = syn.Elements("more_people");
  for (std::size_t i = 0; i < people.size(); ++i) {
    framework::ConfigSection& e = people[i];
    SyntheticPersonParams p = first;
    std::vector<double> torso = {p.torso_W.x(), p.torso_W.y(), p.torso_W.z()};
    if (e.Read("torso", &torso, framework::Check<std::vector<double>>(Three))) p.torso_W = {torso[0], torso[1], torso[2]};
    e.Read("facing_yaw", &p.facing_yaw);
    int seed = static_cast<int>(first.seed + i + 1);
    e.Read("seed", &seed, framework::NonNegative<int>());
    p.seed = static_cast<uint64_t>(seed);
    out.push_back(p);
  }
  return out;
}

}  // namespace

SyntheticPersonParams ReadSyntheticPerson(framework::ConfigSection& syn, ScriptStart* start,
                                          std::vector<SyntheticPersonParams>* others) {
  SyntheticPersonParams p;
  std::vector<double> torso = {p.torso_W.x(), p.torso_W.y(), p.torso_W.z()};
  if (syn.Read("torso", &torso, framework::Check<std::vector<double>>(Three))) p.torso_W = {torso[0], torso[1], torso[2]};
  syn.Read("facing_yaw", &p.facing_yaw);
  syn.Read("noise_stddev", &p.noise_stddev, framework::NonNegative<double>());
  syn.Read("variation", &p.variation, framework::NonNegative<double>());
  syn.Read("transition", &p.transition, framework::NonNegative<double>());
  std::vector<double> rest;
  if (syn.Read("rest_hand", &rest)) {
    if (rest.size() == 3) p.rest_left_P = {rest[0], rest[1], rest[2]};
    else syn.AddError("rest_hand", "must be [x, y, z] (m)");
  }
  int seed = static_cast<int>(p.seed);
  syn.Read("seed", &seed, framework::NonNegative<int>());
  p.seed = static_cast<uint64_t>(seed);
  std::string start_text = "loop";
  syn.Read("start", &start_text, framework::OneOf({"loop", "episodes"}));
  *start = start_text == "episodes" ? ScriptStart::kEpisodes : ScriptStart::kLoop;
  p.loop = *start == ScriptStart::kLoop;

  if (syn.Has("actions")) {
    framework::ConfigSection actions = syn.Section("actions");
    p.actions.clear();
    for (const std::string& name : actions.Keys()) {
      framework::ConfigSection a = actions.Section(name);
      ActionMotion m;
      m.name = name;
      std::string motion = "reach", hand = "right";
      a.Require("motion", &motion, framework::OneOf({"reach", "work", "rest"}));
      a.Read("hand", &hand, framework::OneOf({"left", "right"}));
      m.kind = motion == "reach" ? MotionKind::kReach : motion == "work" ? MotionKind::kWork : MotionKind::kRest;
      m.right_hand = hand == "right";
      std::vector<double> target = {m.target_W.x(), m.target_W.y(), m.target_W.z()};
      if (m.kind != MotionKind::kRest) a.Require("target", &target, framework::Check<std::vector<double>>(Three));
      if (target.size() == 3) m.target_W = {target[0], target[1], target[2]};
      a.Read("period", &m.period, framework::Positive<double>());
      a.Read("amplitude", &m.amplitude, framework::NonNegative<double>());
      p.actions.push_back(m);
    }
    if (p.actions.empty()) syn.AddError("actions", "at least one action is needed");
  }
  std::vector<std::string> script;
  std::vector<double> durations;
  syn.Read("script", &script);
  syn.Read("durations", &durations);
  if (script.size() != durations.size()) {
    syn.AddError("durations", "must have one duration (s) per script step (" + std::to_string(script.size()) + ")");
  } else {
    for (size_t i = 0; i < script.size(); ++i) p.script.push_back({script[i], durations[i]});
  }
  if (const std::string why = p.Validate(); !why.empty() && !p.actions.empty()) syn.AddError("script", why);
  std::vector<SyntheticPersonParams> more = ReadMorePeople(syn, p);
  if (others) *others = std::move(more);
  return p;
}

}  // namespace iplan::perception

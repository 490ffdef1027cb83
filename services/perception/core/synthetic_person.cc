#include "synthetic_person.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>

#include "person_body.h"

namespace iplan::perception {
namespace {

constexpr double kShoulderHalfWidth = 0.18;
constexpr double kPi = 3.14159265358979323846;
constexpr double kWorkHalfSpread = 0.10;  // m, each hand from the work centre

// Keeps a hand within arm's reach of its shoulder.
Eigen::Vector3d WithinReach(const Eigen::Vector3d& shoulder, const Eigen::Vector3d& hand) {
  const Eigen::Vector3d d = hand - shoulder;
  return d.norm() > kMaxReach ? Eigen::Vector3d(shoulder + d.normalized() * kMaxReach) : hand;
}

uint64_t Mix(uint64_t x) {  // splitmix64 finaliser
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

std::string SyntheticPersonParams::Validate() const {
  if (!(noise_stddev >= 0)) return "noise_stddev must be >= 0";
  if (!(variation >= 0)) return "variation must be >= 0";
  if (!(transition >= 0)) return "transition must be >= 0";
  if (!torso_W.allFinite() || !rest_left_P.allFinite() || !std::isfinite(facing_yaw)) {
    return "torso, rest_hand and facing_yaw must be finite";
  }
  if (actions.empty()) return "at least one action is needed";
  for (size_t i = 0; i < actions.size(); ++i) {
    const ActionMotion& a = actions[i];
    if (a.name.empty()) return "action " + std::to_string(i) + " has no name";
    for (size_t j = 0; j < i; ++j) {
      if (actions[j].name == a.name) return "action '" + a.name + "' is defined twice";
    }
    if (!(a.period > 0)) return "action '" + a.name + "': period must be > 0";
    if (!(a.amplitude >= 0)) return "action '" + a.name + "': amplitude must be >= 0";
    if (!a.target_W.allFinite()) return "action '" + a.name + "': target must be finite";
  }
  for (const ScriptStep& s : script) {
    if (std::none_of(actions.begin(), actions.end(), [&](const ActionMotion& a) { return a.name == s.action; })) {
      return "script step '" + s.action + "' names no defined action";
    }
    if (!(s.duration > 0) || !std::isfinite(s.duration)) return "script step '" + s.action + "': duration must be > 0";
  }
  return "";
}

const std::vector<std::string>& UpperBodyJointNames() {
  static const std::vector<std::string> kNames = {"head",       "neck",    "torso",  "shoulder_l", "elbow_l",
                                                  "hand_l",     "shoulder_r", "elbow_r", "hand_r"};
  return kNames;
}

SyntheticPerson::SyntheticPerson(const SyntheticPersonParams& params)
    : params_(params), script_start_(params.loop ? 0.0 : std::numeric_limits<double>::quiet_NaN()), rng_(params.seed) {
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
  for (const ScriptStep& s : params_.script) {
    const auto it = std::find_if(params_.actions.begin(), params_.actions.end(),
                                 [&](const ActionMotion& a) { return a.name == s.action; });
    step_action_.push_back(static_cast<int>(it - params_.actions.begin()));
    script_length_ += s.duration;
  }
}

void SyntheticPerson::StartScript(double t) {
  script_start_ = t;
  ++episode_;
}

SyntheticPerson::Phase SyntheticPerson::PhaseAt(double t) const {
  Phase p;
  const int n = static_cast<int>(params_.script.size());
  if (n == 0) {
    p.since = t;
    return p;
  }
  if (std::isnan(script_start_) || t < script_start_) {  // not started: the last step's action
    p.step = n - 1;
    p.action = step_action_[n - 1];
    p.since = t;
    return p;
  }
  double u = t - script_start_;
  if (params_.loop) {
    p.cycle = static_cast<long>(std::floor(u / script_length_));
    u -= static_cast<double>(p.cycle) * script_length_;
  }
  double begin = 0;
  int k = 0;
  for (; k < n - 1 && u >= begin + params_.script[k].duration; ++k) begin += params_.script[k].duration;
  p.step = k;
  p.action = step_action_[k];
  p.since = u - begin;
  if (k > 0 || p.cycle > 0) {
    p.previous = k > 0 ? k - 1 : n - 1;
    p.previous_end = params_.script[p.previous].duration;
  }
  return p;
}

const std::string& SyntheticPerson::ActionAt(double t) const { return params_.actions[PhaseAt(t).action].name; }

void SyntheticPerson::Hands(int action, double since, long key, Eigen::Vector3d* left, Eigen::Vector3d* right) const {
  const ActionMotion& a = params_.actions[action];
  const Eigen::Matrix3d R_WP = Eigen::AngleAxisd(params_.facing_yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d rest_l = params_.torso_W + R_WP * params_.rest_left_P;
  const Eigen::Vector3d rest_r =
      params_.torso_W + R_WP * Eigen::Vector3d(params_.rest_left_P.x(), -params_.rest_left_P.y(), params_.rest_left_P.z());
  const long repetition = static_cast<long>(std::floor(since / a.period));
  // Per-repetition offset of the target: seeded by the person, the episode
  // and script position (key) and the repetition.
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  if (params_.variation > 0) {
    std::mt19937_64 g(Mix(params_.seed ^ Mix(static_cast<uint64_t>(key) ^ Mix(static_cast<uint64_t>(
                                                  a.kind == MotionKind::kWork ? 0 : repetition)))));
    std::normal_distribution<double> n(0.0, params_.variation);
    offset = {n(g), n(g), 0.5 * n(g)};
  }
  const double phase = std::fmod(since, a.period) / a.period;
  switch (a.kind) {
    case MotionKind::kReach: {
      // Out in the first 40 % of the period, hold, back in the next 40 %, hold.
      const double s = phase < 0.5 ? MinJerk(phase / 0.4) : 1.0 - MinJerk((phase - 0.5) / 0.4);
      const Eigen::Vector3d target = a.target_W + offset;
      *left = rest_l;
      *right = rest_r;
      Eigen::Vector3d& hand = a.right_hand ? *right : *left;
      hand += s * (target - hand);
      break;
    }
    case MotionKind::kWork: {
      const Eigen::Vector3d centre = a.target_W + offset;
      const Eigen::Vector3d side = R_WP * Eigen::Vector3d::UnitY();  // to the person's left
      const Eigen::Vector3d fwd = R_WP * Eigen::Vector3d::UnitX();
      const double w = 2 * kPi * phase;
      *left = centre + kWorkHalfSpread * side + a.amplitude * (std::cos(w) * fwd + std::sin(w) * side);
      *right = centre - kWorkHalfSpread * side + a.amplitude * (std::cos(w + kPi) * fwd + std::sin(w + kPi) * side);
      break;
    }
    case MotionKind::kRest: {
      const double s = a.amplitude * std::sin(2 * kPi * phase);
      *left = rest_l + Eigen::Vector3d(0, 0, s) + 0.3 * offset;
      *right = rest_r + Eigen::Vector3d(0, 0, -s) + 0.3 * offset;
      break;
    }
  }
}

std::vector<JointSample> SyntheticPerson::TruePose(double t) const {
  const Eigen::Matrix3d R_WP = Eigen::AngleAxisd(params_.facing_yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  auto W = [&](const Eigen::Vector3d& p_P) -> Eigen::Vector3d { return params_.torso_W + R_WP * p_P; };
  const Eigen::Vector3d neck = W({0, 0, kTorsoToNeck});
  const Eigen::Vector3d head = W({0, 0, kTorsoToNeck + kNeckToHead});
  const Eigen::Vector3d shoulder_l = W({0, kShoulderHalfWidth, kTorsoToNeck - kShoulderBelowNeck});
  const Eigen::Vector3d shoulder_r = W({0, -kShoulderHalfWidth, kTorsoToNeck - kShoulderBelowNeck});

  const Phase p = PhaseAt(t);
  const auto key = [&](long cycle, int step) {
    return (static_cast<long>(episode_) << 40) ^ (cycle << 8) ^ static_cast<long>(step + 1);
  };
  Eigen::Vector3d hand_l, hand_r;
  Hands(p.action, p.since, key(p.cycle, p.step), &hand_l, &hand_r);
  if (p.previous >= 0 && p.since < params_.transition) {
    Eigen::Vector3d prev_l, prev_r;
    const long prev_cycle = p.step > 0 ? p.cycle : p.cycle - 1;
    Hands(step_action_[p.previous], p.previous_end, key(prev_cycle, p.previous), &prev_l, &prev_r);
    const double s = MinJerk(p.since / params_.transition);
    hand_l = prev_l + s * (hand_l - prev_l);
    hand_r = prev_r + s * (hand_r - prev_r);
  }
  hand_l = WithinReach(shoulder_l, hand_l);
  hand_r = WithinReach(shoulder_r, hand_r);
  const Eigen::Vector3d p9[9] = {head,   neck,   params_.torso_W,        shoulder_l, ArmElbow(shoulder_l, hand_l),
                                 hand_l, shoulder_r, ArmElbow(shoulder_r, hand_r), hand_r};
  std::vector<JointSample> out;
  out.reserve(9);
  for (int i = 0; i < 9; ++i) out.push_back({UpperBodyJointNames()[i], p9[i], 0.0});
  return out;
}

std::vector<JointSample> SyntheticPerson::Observe(double t) {
  std::vector<JointSample> out = TruePose(t);
  std::normal_distribution<double> noise(0.0, params_.noise_stddev);
  for (auto& j : out) {
    for (int k = 0; k < 3; ++k) j.position_W[k] += noise(rng_);
    j.variance = params_.noise_stddev * params_.noise_stddev;
  }
  return out;
}

std::vector<bool> SyntheticPerson::Reaching(double t) const {
  std::vector<bool> out(UpperBodyJointNames().size(), false);
  const Phase p = PhaseAt(t);
  const ActionMotion& a = params_.actions[p.action];
  if (a.kind != MotionKind::kReach || (p.previous >= 0 && p.since < params_.transition)) return out;
  const double phase = std::fmod(p.since, a.period) / a.period;
  out[a.right_hand ? 8 : 5] = phase < 0.4 || (phase >= 0.5 && phase < 0.9);
  return out;
}

namespace {

// Row k of `seq`: the person observed at time t, and its reaching flags.
void RecordFrame(SyntheticPerson& person, double t, int k, intent::SkeletonSequence* seq) {
  const auto pose = person.Observe(t);
  const std::vector<bool> reaching = person.Reaching(t);
  for (size_t j = 0; j < pose.size(); ++j) {
    seq->positions.block<1, 3>(k, 3 * static_cast<Eigen::Index>(j)) = pose[j].position_W.transpose();
    seq->reaching(k, static_cast<Eigen::Index>(j)) = reaching[j];
  }
}

// The draws that make simulated people differ (kept across people: the
// normal distribution caches its second value).
struct PersonDraws {
  std::mt19937_64 g;
  std::normal_distribution<double> jitter{0.0, 1.0};
  std::uniform_real_distribution<double> unit{0.0, 1.0};
};

// A simulated person of `params`: standing a little differently, moving at their own pace.
SyntheticPersonParams Individual(const SyntheticPersonParams& params, PersonDraws& d, double* pace) {
  SyntheticPersonParams p = params;
  p.torso_W += Eigen::Vector3d(0.03 * d.jitter(d.g), 0.03 * d.jitter(d.g), 0.02 * d.jitter(d.g));
  *pace = 0.85 + 0.3 * d.unit(d.g);
  for (ActionMotion& a : p.actions) a.period *= *pace;
  p.loop = false;
  return p;
}

std::string SubjectName(int s) {
  char subject[16];
  std::snprintf(subject, sizeof(subject), "s%02d", s);
  return subject;
}

}  // namespace

intent::SkeletonDataset RecordDemonstrations(const SyntheticPersonParams& params, int subjects, int repetitions,
                                             double seconds, double rate_hz) {
  if (subjects < 1 || repetitions < 1 || !(seconds > 0) || !(rate_hz > 0)) {
    throw std::invalid_argument("RecordDemonstrations: subjects, repetitions, seconds and rate must be positive");
  }
  intent::SkeletonDataset data;
  data.joint_names = UpperBodyJointNames();
  const int frames = std::max(2, static_cast<int>(std::floor(seconds * rate_hz)));
  PersonDraws d{std::mt19937_64(Mix(params.seed * 7919 + 17))};
  for (int s = 1; s <= subjects; ++s) {
    double pace = 1.0;
    const SyntheticPersonParams p = Individual(params, d, &pace);
    const std::string subject = SubjectName(s);
    for (const ActionMotion& a : p.actions) {
      for (int r = 1; r <= repetitions; ++r) {
        SyntheticPersonParams q = p;
        q.seed = Mix(params.seed ^ Mix(static_cast<uint64_t>(s * 1000 + r)));
        q.script = {ScriptStep{a.name, frames / rate_hz + 100.0}};
        SyntheticPerson person(q);
        person.StartScript(0.0);
        const double t0 = d.unit(d.g) * a.period * pace;  // start anywhere in the motion
        intent::SkeletonSequence seq;
        seq.id = "synthetic_" + a.name + "_" + subject + "_e" + std::to_string(r);
        seq.subject = subject;
        seq.action = a.name;
        seq.time.resize(frames);
        seq.positions.resize(frames, 3 * static_cast<Eigen::Index>(data.joint_names.size()));
        seq.reaching.resize(frames, static_cast<Eigen::Index>(data.joint_names.size()));
        for (int k = 0; k < frames; ++k) {
          seq.time[k] = k / rate_hz;
          RecordFrame(person, t0 + k / rate_hz, k, &seq);
        }
        data.sequences.push_back(std::move(seq));
      }
    }
  }
  return data;
}

intent::SkeletonDataset RecordEpisodes(const SyntheticPersonParams& params, int people, int episodes, double lead,
                                       double tail, double rate_hz) {
  if (people < 1 || episodes < 1 || !(lead >= 0) || !(tail >= 0) || !(rate_hz > 0)) {
    throw std::invalid_argument("RecordEpisodes: people, episodes and rate must be positive, lead and tail >= 0");
  }
  if (params.script.empty()) throw std::invalid_argument("RecordEpisodes: the person has no script");
  intent::SkeletonDataset data;
  data.joint_names = UpperBodyJointNames();
  double script_length = 0;
  for (const ScriptStep& step : params.script) script_length += step.duration;
  const int frames = static_cast<int>(std::floor((lead + script_length + tail) * rate_hz)) + 1;
  PersonDraws d{std::mt19937_64(Mix(params.seed * 7919 + 29))};
  for (int s = 1; s <= people; ++s) {
    double pace = 1.0;
    const SyntheticPersonParams p = Individual(params, d, &pace);
    const std::string subject = SubjectName(s);
    for (int r = 1; r <= episodes; ++r) {
      SyntheticPersonParams q = p;
      q.seed = Mix(params.seed ^ Mix(static_cast<uint64_t>(s * 1000 + 500 + r)));
      SyntheticPerson person(q);
      person.StartScript(lead);
      intent::SkeletonSequence seq;
      seq.id = "synthetic_episode_" + subject + "_e" + std::to_string(r);
      seq.subject = subject;
      seq.action = params.script.front().action;
      seq.time.resize(frames);
      seq.positions.resize(frames, 3 * static_cast<Eigen::Index>(data.joint_names.size()));
      seq.reaching.resize(frames, static_cast<Eigen::Index>(data.joint_names.size()));
      seq.frame_actions.resize(frames);
      for (int k = 0; k < frames; ++k) {
        seq.time[k] = k / rate_hz;
        RecordFrame(person, k / rate_hz, k, &seq);
        seq.frame_actions[k] = person.ActionAt(k / rate_hz);
      }
      data.sequences.push_back(std::move(seq));
    }
  }
  return data;
}

}  // namespace iplan::perception

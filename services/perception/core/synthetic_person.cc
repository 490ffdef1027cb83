#include "synthetic_person.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace iplan::perception {
namespace {

constexpr double kUpperArm = 0.30;   // m
constexpr double kForearm = 0.28;    // m
constexpr double kShoulderHalfWidth = 0.18;
constexpr double kTorsoToNeck = 0.30;
constexpr double kNeckToHead = 0.18;

// Minimum-jerk position profile s(u), u in [0, 1].
double MinJerk(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * u * (10 - 15 * u + 6 * u * u);
}

// Elbow position for a two-link arm from shoulder to hand, bending down.
Eigen::Vector3d Elbow(const Eigen::Vector3d& shoulder, const Eigen::Vector3d& hand) {
  const Eigen::Vector3d d = hand - shoulder;
  const double dist = std::clamp(d.norm(), 1e-6, kUpperArm + kForearm - 1e-6);
  const double a = (kUpperArm * kUpperArm - kForearm * kForearm + dist * dist) / (2 * dist);
  const double h = std::sqrt(std::max(0.0, kUpperArm * kUpperArm - a * a));
  const Eigen::Vector3d dir = d / d.norm();
  Eigen::Vector3d down = Eigen::Vector3d::UnitZ().cross(dir).cross(dir);  // perpendicular, pointing down
  if (down.norm() < 1e-9) down = Eigen::Vector3d::UnitX();
  down.normalize();
  if (down.z() > 0) down = -down;
  return shoulder + a * dir + h * down;
}

}  // namespace

std::string SyntheticPersonParams::Validate() const {
  if (!(reach_period > 0)) return "reach_period must be > 0";
  if (!(noise_stddev >= 0)) return "noise_stddev must be >= 0";
  if (!torso_W.allFinite() || !reach_target_W.allFinite()) return "positions must be finite";
  return "";
}

const std::vector<std::string>& UpperBodyJointNames() {
  static const std::vector<std::string> kNames = {"head",       "neck",    "torso",  "shoulder_l", "elbow_l",
                                                  "hand_l",     "shoulder_r", "elbow_r", "hand_r"};
  return kNames;
}

SyntheticPerson::SyntheticPerson(const SyntheticPersonParams& params) : params_(params), rng_(params.seed) {}

std::vector<JointSample> SyntheticPerson::TruePose(double t) const {
  const Eigen::Matrix3d R_WP = Eigen::AngleAxisd(params_.facing_yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // Person frame P: x forward (where they face), y to their left, z up.
  auto W = [&](const Eigen::Vector3d& p_P) -> Eigen::Vector3d { return params_.torso_W + R_WP * p_P; };
  const Eigen::Vector3d neck = W({0, 0, kTorsoToNeck});
  const Eigen::Vector3d head = W({0, 0, kTorsoToNeck + kNeckToHead});
  const Eigen::Vector3d shoulder_l = W({0, kShoulderHalfWidth, kTorsoToNeck - 0.05});
  const Eigen::Vector3d shoulder_r = W({0, -kShoulderHalfWidth, kTorsoToNeck - 0.05});
  const Eigen::Vector3d hand_l = W({0.15, 0.25, -0.10});
  const Eigen::Vector3d rest_r = W({0.15, -0.25, -0.10});
  // Out in the first half of the period, back in the second, with a pause.
  const double phase = std::fmod(t, params_.reach_period) / params_.reach_period;
  const double s = phase < 0.5 ? MinJerk(phase / 0.4) : 1.0 - MinJerk((phase - 0.5) / 0.4);
  Eigen::Vector3d hand_r = rest_r + s * (params_.reach_target_W - rest_r);
  // Keep the hand within arm's reach.
  const Eigen::Vector3d d = hand_r - shoulder_r;
  if (d.norm() > 0.97 * (kUpperArm + kForearm)) hand_r = shoulder_r + d.normalized() * 0.97 * (kUpperArm + kForearm);
  const std::array<Eigen::Vector3d, 9> p = {head,   neck,       params_.torso_W, shoulder_l,
                                            Elbow(shoulder_l, hand_l), hand_l, shoulder_r,
                                            Elbow(shoulder_r, hand_r), hand_r};
  std::vector<JointSample> out;
  out.reserve(9);
  for (int i = 0; i < 9; ++i) out.push_back({UpperBodyJointNames()[i], p[i], 0.0});
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

}  // namespace iplan::perception

// A simulated person standing across the table from the robot, reaching
// with the right hand towards a target and back (minimum-jerk profile), with
// seeded Gaussian sensor noise. No DDS types: positions in the cell's world
// frame (x forward from the robot base, z up), metres and seconds.
#pragma once

#include <array>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace iplan::perception {

struct SyntheticPersonParams {
  Eigen::Vector3d torso_W{1.0, 0.0, 1.05};     ///< m, torso joint in the world frame
  double facing_yaw = 3.14159265358979;        ///< rad, direction the person faces (pi: towards -x)
  Eigen::Vector3d reach_target_W{0.62, 0.10, 0.95};  ///< m, where the right hand reaches
  double reach_period = 4.0;                   ///< s, one reach out and back
  double noise_stddev = 0.01;                  ///< m, per coordinate sensor noise
  uint64_t seed = 1;                           ///< noise generator seed

  /// Empty when valid, else the reason.
  std::string Validate() const;
};

struct JointSample {
  std::string name;
  Eigen::Vector3d position_W;
  double variance = 0;  ///< m^2 per coordinate (isotropic)
};

/// The 9 upper-body joints of METHOD 1, in this order.
const std::vector<std::string>& UpperBodyJointNames();

class SyntheticPerson {
 public:
  explicit SyntheticPerson(const SyntheticPersonParams& params);
  /// True pose at time t (s since start). Deterministic, allocates the result.
  std::vector<JointSample> TruePose(double t) const;
  /// TruePose plus sensor noise; variance = noise_stddev^2. Advances the
  /// generator (not thread-safe).
  std::vector<JointSample> Observe(double t);

 private:
  SyntheticPersonParams params_;
  std::mt19937_64 rng_;
};

}  // namespace iplan::perception

// A simulated person standing across the table from the robot and doing
// their part of the task: a script of named actions (the task graph's human
// actions), each performed with a human-like motion (minimum-jerk reaches,
// two-handed work, rest), varied between repetitions and observed with seeded
// Gaussian sensor noise. No DDS types: positions in the cell's world frame
// (x forward from the robot base, z up), metres and seconds. The pose is a
// deterministic function of time, the script start and the seed, so that the
// true pose (for contact counting) and the observed one always agree.
#pragma once

#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/intent/skeleton_data.h"

namespace iplan::perception {

/// How an action moves the hands.
enum class MotionKind {
  kReach,  ///< one hand reaches to `target_W` and back every `period`
  kWork,   ///< both hands work around `target_W` (small circles of `amplitude`)
  kRest,   ///< hands at rest, swaying by `amplitude`
};

struct ActionMotion {
  std::string name;                            ///< action label (e.g. the task graph's human action)
  MotionKind kind = MotionKind::kReach;
  bool right_hand = true;                      ///< kReach: which hand reaches
  Eigen::Vector3d target_W{0.62, 0.10, 0.95};  ///< m; kReach: hand target, kWork: centre between the hands
  double period = 4.0;                         ///< s; one reach out and back, one work circle, one sway
  double amplitude = 0.04;                     ///< m; kWork: circle radius, kRest: sway
};

/// One step of the person's script: do `action` for `duration` seconds.
struct ScriptStep {
  std::string action;
  double duration = 1.0;  ///< s
};

struct SyntheticPersonParams {
  Eigen::Vector3d torso_W{1.0, 0.0, 1.05};     ///< m, torso joint in the world frame
  double facing_yaw = 3.14159265358979;        ///< rad, direction the person faces (pi: towards -x)
  double noise_stddev = 0.01;                  ///< m, per coordinate sensor noise
  /// m, the left hand at rest relative to the torso joint, in the person
  /// frame (x forward, y to their left, z up); the right hand is mirrored.
  Eigen::Vector3d rest_left_P{0.25, 0.20, -0.25};
  uint64_t seed = 1;                           ///< noise and variation seed
  /// The actions the person can do. Default: a single right-hand reach.
  std::vector<ActionMotion> actions = {ActionMotion{"reach"}};
  /// The script; empty: the first action for ever.
  std::vector<ScriptStep> script;
  /// After the last step: start the script again (true), or keep doing the
  /// last step's action until the next StartScript (false).
  bool loop = true;
  double variation = 0.0;   ///< m, std dev of the per-repetition offset of each target
  double transition = 0.5;  ///< s, blend of the hands from one action into the next

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
  /// Throws std::invalid_argument when `params` are invalid.
  explicit SyntheticPerson(const SyntheticPersonParams& params);
  /// Restarts the script at time `t` (s, same clock as TruePose); each start
  /// is a new episode with its own variation. With loop = true the script
  /// also starts by itself at t = 0.
  void StartScript(double t);
  int episode() const { return episode_; }
  /// The action performed at time t (the ground-truth label).
  const std::string& ActionAt(double t) const;
  /// True pose at time t (s). Deterministic, allocates the result.
  std::vector<JointSample> TruePose(double t) const;
  /// TruePose plus sensor noise; variance = noise_stddev^2. Advances the
  /// generator (not thread-safe).
  std::vector<JointSample> Observe(double t);
  /// Per joint of UpperBodyJointNames() at time t (s): whether it is
  /// reaching, i.e. moving towards a goal: the hand of a reach action while it
  /// goes out to the target (the first 40 % of the period) or back to rest
  /// (50 to 90 %), outside the blend from a previous action. Deterministic.
  std::vector<bool> Reaching(double t) const;

 private:
  struct Phase {
    int step = -1;          // script step (-1: no script, the first action)
    int action = 0;         // index into params_.actions
    double since = 0;       // s since the step began
    int previous = -1;      // step before it (-1: none), for the transition
    double previous_end = 0;  // s, when that step ended (absolute)
    long cycle = 0;         // script repetition (loop)
  };
  Phase PhaseAt(double t) const;
  void Hands(int action, double since, long repetition_key, Eigen::Vector3d* left, Eigen::Vector3d* right) const;

  SyntheticPersonParams params_;
  std::vector<int> step_action_;  // script step -> action index
  double script_length_ = 0;
  double script_start_;
  int episode_ = 0;
  std::mt19937_64 rng_;
};

/// Demonstrations of every action for training the intent models: for each
/// of `subjects` simulated people (torso position, speed and targets varied
/// by subject) and each action, `repetitions` sequences of `seconds` at
/// `rate_hz`, observed with the params' sensor noise. Subjects are named
/// s01, s02, ...; joints are UpperBodyJointNames(); every sequence carries
/// its reaching flags (SyntheticPerson::Reaching). Deterministic for a seed.
intent::SkeletonDataset RecordDemonstrations(const SyntheticPersonParams& params, int subjects, int repetitions,
                                             double seconds, double rate_hz);

/// Episodes of the person's script as the cell plays it (perception.synthetic
/// start: episodes): for each of `people` simulated people (varied as in
/// RecordDemonstrations) `episodes` recordings at `rate_hz`, each `lead`
/// seconds before the script starts (the person idles in the last step's
/// action), the whole script and `tail` seconds after it. Every frame carries
/// its action (SkeletonSequence::frame_actions, the script's) and reaching
/// flags; the sequence's own label is the script's first action. Subjects s01,
/// s02, ...; joints UpperBodyJointNames(). Deterministic for a seed. Throws
/// std::invalid_argument for a person without a script or bad counts.
intent::SkeletonDataset RecordEpisodes(const SyntheticPersonParams& params, int people, int episodes, double lead,
                                       double tail, double rate_hz);

}  // namespace iplan::perception

// Features of METHOD section 2 computed from a window of skeleton frames.
//
// A window is the last T frames of a track at the model rate, as a (T, 3 J)
// matrix of joint positions in the world (sensor) frame W, oldest row first.
// If fewer than T frames have been observed the window is padded at the front
// by repeating the oldest observed frame (the person is taken to have been
// still before tracking started).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace iplan::intent {

/// Which joints the model uses and how the torso and hands are defined.
/// Any joint set works, from one joint (a tracked wrist) to a full body; the
/// names are those of the data and never interpreted, except by the defaults
/// (DefaultJointConfig, ResolveJointConfig) and the optional body-size
/// normalisation (FrameFeatureOptions::normalise_body_size).
struct JointConfig {
  /// Model joints, in output order (J >= 1 names). Every name must exist in the data.
  std::vector<std::string> joints;
  /// The torso reference point p_WT is the mean of these joints (names from
  /// `joints`), e.g. {"torso"} or {"shoulder_l", "shoulder_r"}. "Relative to
  /// the torso" in the features means relative to p_WT:
  ///  - a joint of its own, e.g. {"wrist_r"} for a one-joint model: that
  ///    joint's posture block is zero, the torso-motion block and the
  ///    forecaster's torso velocity and displacement carry its own motion;
  ///    the features do not depend on where the person is (translation
  ///    invariant), only on how the joints move;
  ///  - empty (no torso, "none"): p_WT is the origin of W, so the features
  ///    are absolute positions in W (posture block = p_WJ, torso-motion,
  ///    torso velocity and displacement blocks = 0); the model then depends on
  ///    where in W the motion happens (use it when the data frame is the cell's
  ///    world frame and the location itself is telling).
  std::vector<std::string> torso;
  /// Hand joints (names from `joints`) used for hand-object distances; may be
  /// empty (then, or without objects, there are no hand-object features).
  std::vector<std::string> hands;
  /// Task object positions p_WO (metres, frame W). May be empty: datasets
  /// without objects simply have no hand-object features.
  std::vector<Eigen::Vector3d> objects;

  /// Returns an empty string when valid, otherwise what is wrong, naming the
  /// joint (empty joint list, empty or duplicate joint name, torso/hand name
  /// not among `joints`, duplicate torso/hand name, non-finite object).
  std::string Validate() const;
};

/// A joint set as configured (CLI --joints/--torso/--hands, a config file):
/// every part that is set is used as given; only the unset parts get a
/// default, computed from the chosen joints (not from the data's).
struct JointSelection {
  /// Model joints; unset: the default upper-body set found in the data, or,
  /// when fewer than two of its joints are there (a one-joint wrist tracker,
  /// a tracker with names of its own), every joint of the data.
  std::optional<std::vector<std::string>> joints;
  /// Torso reference joints; unset: the default among `joints` (torso or
  /// spine, else shoulder_l and shoulder_r, else all of `joints`: for one
  /// joint the joint itself); set and empty: no torso (see JointConfig::torso).
  std::optional<std::vector<std::string>> torso;
  /// Hand joints; unset: hand_l/hand_r, else wrist_l/wrist_r, among `joints`;
  /// set and empty: none.
  std::optional<std::vector<std::string>> hands;
};

/// Options of the per-frame classifier features.
struct FrameFeatureOptions {
  /// Weight of the torso-motion block relative to the posture block (>= 0).
  double torso_motion_weight = 1.0;
  /// If true and both shoulder_l and shoulder_r are model joints, posture and
  /// torso motion are divided by the window's mean shoulder width and
  /// multiplied by 0.35 m (a typical adult width), removing body-size
  /// differences between people while keeping the unit metres.
  bool normalise_body_size = false;
};

/// Picks the default upper-body joint set (METHOD 1: head, neck, torso,
/// shoulder/elbow/hand left and right) from the joints a dataset provides,
/// accepting the usual aliases: neck = shoulder_center, torso = spine, hand =
/// wrist when there is no hand joint. Joints the dataset lacks are left out;
/// when there is no torso joint the torso is the mean of the shoulders.
/// Data with fewer than two of these joints (a one-joint wrist tracker, a
/// tracker with names of its own) gets every joint it has, the torso being
/// their mean (one joint: itself). Hands are hand_l/hand_r, else
/// wrist_l/wrist_r, when present. Same as ResolveJointConfig(available, {}).
/// Throws std::invalid_argument when the data has no joints.
JointConfig DefaultJointConfig(const std::vector<std::string>& available);

/// The joint configuration for data providing the joints `available`: the
/// parts set in `selection` as given, defaults (see JointSelection) only for
/// the unset ones. Objects are left empty.
/// Throws std::invalid_argument, naming the joint, when a selected joint is
/// not in `available`, when the data has no joints, or
/// when the result is invalid (JointConfig::Validate, e.g. a torso joint that
/// is not a model joint).
JointConfig ResolveJointConfig(const std::vector<std::string>& available,
                               const JointSelection& selection);

/// Index helpers derived from a validated JointConfig.
class FeatureLayout {
 public:
  /// Throws std::invalid_argument with JointConfig::Validate()'s message.
  explicit FeatureLayout(const JointConfig& config,
                         const FrameFeatureOptions& options = FrameFeatureOptions{});

  int num_joints() const { return num_joints_; }
  /// Per-frame classifier feature size: 3 J + 3 + (hands x objects).
  int frame_feature_size() const { return 3 * num_joints_ + 3 + num_object_features(); }
  /// Forecaster input size: 3 J (current pose relative to torso) + 3 J
  /// (joint velocity relative to torso) + 3 (torso velocity) + 3 (torso
  /// displacement over the window) + hands x objects + 3 J x
  /// `history_samples` (each joint's displacement since earlier rows).
  int forecast_input_size(int history_samples = 0) const {
    return 6 * num_joints_ + 6 + num_object_features() + 3 * num_joints_ * history_samples;
  }
  int num_object_features() const {
    return static_cast<int>(hand_index_.size() * objects_.size());
  }

  /// Torso reference p_WT of one frame row (3 J) in metres, frame W; the
  /// origin of W when the configuration has no torso joints.
  Eigen::Vector3d Torso(const Eigen::Ref<const Eigen::RowVectorXd>& frame) const;

  /// Per-frame classifier features of a padded window (T, 3 J): for each row s,
  /// joints relative to that row's torso (3 J), that row's torso relative to
  /// the torso of the newest row (3), distances of each hand to each object
  /// (hands x objects). The torso block is scaled by
  /// options.torso_motion_weight; see FrameFeatureOptions for the body-size
  /// normalisation. Returns (T, frame_feature_size()), metres.
  Eigen::MatrixXd FrameFeatures(const Eigen::MatrixXd& window) const;

  /// True when MirroredWindow() can mirror this joint set: the model joints
  /// include a left/right pair <name>_l / <name>_r of shoulder, hip, elbow,
  /// wrist or hand (the first found gives the lateral axis) and there are no
  /// task objects (a mirrored hand would not be near the same object).
  bool CanMirror() const { return lateral_l_ >= 0; }

  /// The mirror image of a window (T, 3 J, frame W): the same motion done
  /// with the other side of the body. Every row is reflected across the
  /// plane through the window's mean joint position whose normal is the
  /// window's mean lateral direction (pair joint _l minus _r), and every
  /// <name>_l joint trades places with its <name>_r (a joint without a
  /// partner stays). Used to train the classifier on both handednesses.
  /// Requires CanMirror() (throws std::logic_error otherwise).
  Eigen::MatrixXd MirroredWindow(const Eigen::MatrixXd& window) const;

  /// Forecaster input vector of a padded window (T, 3 J) at `rate` Hz (see
  /// forecast_input_size() for the layout); velocities (m/s) are finite
  /// differences over `velocity_frames` frames (clamped to T - 1, >= 1). The
  /// history block (`history_samples` >= 0) holds, for l = 1..n, the
  /// displacement p_now - p_back of every joint (m, frame W) since row
  /// now - floor(l (T - 1) / n): the path of the motion so far, which tells
  /// where in a movement the person is (its phase), back to the oldest row.
  Eigen::VectorXd ForecastInput(const Eigen::MatrixXd& window, double rate,
                                int velocity_frames, int history_samples = 0) const;

 private:
  int num_joints_ = 0;
  std::vector<int> torso_index_;
  std::vector<int> hand_index_;
  std::vector<Eigen::Vector3d> objects_;
  FrameFeatureOptions options_;
  int shoulder_l_ = -1;
  int shoulder_r_ = -1;
  int lateral_l_ = -1, lateral_r_ = -1;  // the pair giving the lateral axis, or -1
  std::vector<int> mirror_partner_;       // joint -> its _l/_r partner (itself if none)
};

/// Returns the padded window of length T ending at row `end` (inclusive) of
/// `positions` (n, 3 J): rows end-T+1..end, rows before 0 replaced by row 0.
/// Requires 0 <= end < n and T >= 1 (asserted by the caller; throws
/// std::out_of_range otherwise).
Eigen::MatrixXd WindowEndingAt(const Eigen::MatrixXd& positions, int end, int T);

}  // namespace iplan::intent

// The person of a simulated scenario, as PersonStreams (true and observed
// skeletons at the sensor rate) from either
//  - recorded motion: a sequence of a skeleton CSV in the shared layout
//    (e.g. assembly.csv: shoulders, elbows and wrists of a seated person),
//    replayed through the perception service's own replay core
//    (perception::SkeletonReplay: joint renaming, sensor-to-world
//    transform), placed across the table; body joints the recording lacks
//    are derived from the shoulders (below); or
//  - the synthetic person of the cell (perception::SyntheticPerson), moved
//    and turned, starting their script at a chosen time, optionally with one
//    hand sweeping along a line (HandSweep: an arm crossing the robot's path).
// Observations are the truth plus seeded Gaussian sensor noise.
//
// Frames and units: world frame W (robot base, x towards the person, z up
// from the table top), m, rad; scenario time in s from the first frame.
// Free functions, thread-safe; they allocate.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "tools/cell_sim/core/interaction_loop.h"
#include "services/perception/core/synthetic_person.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::cell_sim {

/// Where and when a recording plays in the cell.
struct RecordedPlacement {
  /// m, W: where the recording's mean shoulder centre is put.
  Eigen::Vector3d shoulder_centre_W{1.1, 0.0, 0.5};
  double yaw = 0;         ///< rad about the vertical through shoulder_centre_W; 0: facing the robot (-x)
  double clip_start = 0;  ///< s into the recording at which the clip begins
  double delay = 0;       ///< s after the scenario start at which the clip begins (its first pose is held before)
};

/// The pose of the recording's sensor frame S in W that puts the mean
/// shoulder centre c_S of `sequence` (joints shoulder_l, shoulder_r of
/// `data`, before any renaming) at placement.shoulder_centre_W. The sensor
/// is taken to be an optical camera (x right, y down, z away) on the robot's
/// side looking at the person: z_S -> +x_W, x_S -> -y_W, y_S -> -z_W, then
/// turned by placement.yaw. Throws std::invalid_argument when the sequence or
/// the shoulders are missing or never detected together.
Eigen::Isometry3d RecordingPose(const intent::SkeletonDataset& data, const std::string& sequence,
                                const RecordedPlacement& placement);

/// The stream of `sequence` of `data` (`file` names it in messages): its
/// joints renamed by `joint_map` (as perception.replay.joint_map, e.g.
/// wrist_l -> hand_l), transformed by RecordingPose, a joint not detected in
/// a frame held at its last detected position (frames before every joint
/// was seen are skipped), interpolated in time at rate_hz over `duration`
/// s (the last pose held past the recording's end). Body joints the
/// recording lacks are derived from the shoulders, with the synthetic
/// person's proportions: neck 0.05 m above their midpoint, head 0.18 m above
/// the neck, torso 0.30 m below it. Then observed = truth + N(0,
/// noise_std^2 I) per joint and frame, seeded by `seed`.
/// Throws std::invalid_argument when a body joint is neither in the
/// recording nor derivable (head, neck, torso), or on bad arguments.
PersonStream RecordedPersonStream(const intent::SkeletonDataset& data, const std::string& file,
                                  const std::string& sequence, const std::map<std::string, std::string>& joint_map,
                                  const RecordedPlacement& placement, const std::vector<std::string>& body_joints,
                                  double rate_hz, double duration, double noise_std, uint64_t seed);

/// One hand sweeping along a straight line, over whatever the script has it
/// do: from `start` the hand moves from where the script has it to from_W
/// (minimum jerk, `approach` s), along the line to to_W (minimum jerk,
/// `duration` s), and back to where the script has it then (`approach` s).
/// The hand is kept within the synthetic person's reach of its shoulder
/// (0.97 of 0.30 + 0.28 m) and the elbow follows (two-link arm bending down,
/// as the synthetic person's).
struct HandSweep {
  bool right_hand = true;
  Eigen::Vector3d from_W = Eigen::Vector3d::Zero();  ///< m, W
  Eigen::Vector3d to_W = Eigen::Vector3d::Zero();    ///< m, W
  double start = 0;      ///< s, scenario time the hand leaves the script's motion
  double approach = 0.6; ///< s, to from_W and back from to_W; > 0
  double duration = 1.0; ///< s, from from_W to to_W; > 0
  /// s, scenario time the hand is halfway along the line.
  double middle() const { return start + approach + 0.5 * duration; }
  /// Empty when valid, else why not.
  std::string Validate() const;
};

/// Where and when the synthetic person acts.
struct SyntheticPlacement {
  Eigen::Vector3d torso_offset_W = Eigen::Vector3d::Zero();  ///< m, added to the configured torso position
  double yaw = 0;           ///< rad, added to the configured facing direction
  double script_start = 0;  ///< s (scenario time) at which the script starts; may be negative (under way)
  std::optional<HandSweep> sweep;  ///< none: the script alone moves the hands
};

/// The synthetic person of `person` (its targets stay where the table's
/// objects are; its seed, variation and script as given; no loop), moved by
/// the placement, its hand swept by placement.sweep if given, sampled at
/// rate_hz for `duration` s; observed = truth + N(0, noise_std^2 I), seeded
/// by `seed` (the person's own noise generator is not used). Throws
/// std::invalid_argument when a body joint is not one of the person's, on an
/// invalid sweep, a sweep whose hand, elbow or shoulder is not a body joint,
/// or on bad arguments.
PersonStream SyntheticPersonStream(const perception::SyntheticPersonParams& person, const SyntheticPlacement& placement,
                                   const std::vector<std::string>& body_joints, double rate_hz, double duration,
                                   double noise_std, uint64_t seed);

}  // namespace iplan::cell_sim

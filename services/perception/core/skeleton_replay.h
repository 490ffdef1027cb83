// Replays recorded skeleton sequences (the shared CSV layout, read with
// iplan::intent::LoadSkeletonCsv) as if they came from a tracker: frames in
// recorded time (optionally scaled), joints renamed, positions transformed
// from the recording's sensor frame S to the world frame W. No DDS types.
//
// Play time is seconds since the replay started. Sequences play one after
// another, `pause` seconds apart; each play of a sequence is a new body id
// (1, 2, ...), as a tracker gives a new id to a person it sees again.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "services/perception/core/synthetic_person.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::perception {

struct SkeletonReplayParams {
  std::string file;                     ///< CSV in the shared layout
  std::vector<std::string> sequences;   ///< sequence ids to play (file order); empty: all
  std::vector<std::string> subjects;    ///< play only these subjects' sequences; empty: all
  bool loop = false;                    ///< start again after the last sequence
  double rate = 1.0;                    ///< playback speed factor (2: twice as fast), > 0
  double pause = 0.5;                   ///< s of play time between two sequences, >= 0
  double start_delay = 0.0;             ///< s of play time before the first frame, >= 0
  /// CSV joint name -> published name; joints not listed keep their name.
  std::map<std::string, std::string> joint_map;
  Eigen::Isometry3d X_WS = Eigen::Isometry3d::Identity();  ///< pose of the sensor frame in W

  /// Empty when valid, else the offending field and value (file contents are
  /// checked by the SkeletonReplay constructor).
  std::string Validate() const;
};

/// X_WS from a translation (m) and a rotation about the world z axis (rad).
Eigen::Isometry3d TransformFromTranslationYaw(const Eigen::Vector3d& p_WS, double yaw);
/// X_WS from 16 numbers (4x4 homogeneous matrix, row-major). Returns an empty
/// string and sets *X when the matrix is a rigid transform (orthonormal
/// rotation with determinant 1 within 1e-6, last row 0 0 0 1), else the reason.
std::string TransformFromMatrix(const std::vector<double>& m, Eigen::Isometry3d* X);

/// One frame to publish.
struct ReplayFrame {
  double play_time = 0.0;  ///< s since the replay started
  std::uint32_t body_id = 0;
  std::string sequence_id;
  std::string action;
  /// Detected joints only (undetected ones, NaN or 0,0,0 in the file, are
  /// left out), renamed, in W; variance 0 (unknown).
  std::vector<JointSample> joints;
};

class SkeletonReplay {
 public:
  /// Loads and selects the sequences. Throws std::invalid_argument for
  /// invalid params, an unknown sequence id or subject, a joint_map entry
  /// naming a joint the file lacks, a map producing duplicate names, or
  /// nothing to play; std::runtime_error (naming file and line) for an
  /// unreadable file.
  explicit SkeletonReplay(const SkeletonReplayParams& params);
  /// Same, with the file already loaded (params.file is used in messages).
  SkeletonReplay(const SkeletonReplayParams& params, intent::SkeletonDataset data);

  /// The next frame due at play time `now` (s), if any: frames are returned
  /// in play order, each once; call repeatedly until false. A frame with no
  /// detected joint is skipped.
  bool Next(double now, ReplayFrame* out);
  /// True when every frame has been returned (never with loop).
  bool finished() const;
  /// Play time of one pass over the selected sequences, s.
  double pass_duration() const { return pass_duration_; }
  int num_sequences() const { return static_cast<int>(data_.sequences.size()); }
  int frames_per_pass() const { return static_cast<int>(schedule_.size()); }
  /// Joint names of the file after joint_map, in file order.
  const std::vector<std::string>& published_joint_names() const { return names_; }

 private:
  struct Entry {
    double play_time;  // within a pass
    int sequence;
    int row;
  };
  SkeletonReplayParams params_;
  intent::SkeletonDataset data_;
  std::vector<std::string> names_;
  std::vector<Entry> schedule_;
  double pass_duration_ = 0.0;
  std::size_t cursor_ = 0;
  int pass_ = 0;
};

}  // namespace iplan::perception

// Recorded skeleton sequences: the shared CSV layout, joint selection and
// resampling to the model rate.
//
// CSV layout (see ../shared/data/README.md), one row per frame, header first:
//   sequence,subject,action,frame,time,<joint>.x,<joint>.y,<joint>.z,...
// Joint coordinates are metres in the sensor frame S; `time` is seconds from
// the start of the sequence.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace iplan::intent {

/// One recording of one person performing one labelled action.
struct SkeletonSequence {
  std::string id;       ///< Unique id of the recording.
  std::string subject;  ///< Who performed it (used for cross-subject splits).
  std::string action;   ///< Action label of the whole sequence.
  Eigen::VectorXd time;       ///< (n) seconds from the start, strictly increasing.
  Eigen::MatrixXd positions;  ///< (n, 3 J) metres; row i = frame i, joint j in
                              ///< columns 3j..3j+2 (x, y, z), frame S.
  /// (n, J) or empty: whether joint j is reaching in frame i, i.e. moving
  /// towards a goal (out to a target or back to rest). Only data whose
  /// generator knows it (the synthetic person's demonstrations) carry it; the
  /// CSV layout does not. The evaluation scores reaching joints separately.
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> reaching;
  /// (n) or empty: the action of each frame when it changes within the
  /// recording (the synthetic person's scripted episodes); empty: `action`
  /// for every frame. Not part of the CSV layout.
  std::vector<std::string> frame_actions;
};

/// A set of sequences sharing one joint list.
struct SkeletonDataset {
  std::vector<std::string> joint_names;  ///< (J) joint order of `positions`.
  std::vector<SkeletonSequence> sequences;
};

/// Reads a skeleton CSV file in the shared layout. A joint coordinate written
/// as `nan` or left empty marks an undetected joint and is stored as NaN.
/// Throws std::runtime_error naming the file and line for: a missing file, a
/// header without the five leading columns or with joint columns that are not
/// `<name>.x,<name>.y,<name>.z` triples, a row with the wrong number of fields,
/// a field that is not a finite number, a sequence whose rows are not
/// contiguous, or non-increasing time within a sequence.
/// Thread-safe (no shared state). Allocates.
SkeletonDataset LoadSkeletonCsv(const std::string& path);

/// True when a joint position (3) was detected: all coordinates finite and not
/// exactly (0, 0, 0), which trackers such as OpenPose write for a missing
/// joint (it is the sensor origin, never a real body position).
bool JointDetected(const Eigen::Ref<const Eigen::RowVectorXd>& p);

/// Returns the sequences of `data` whose subject is in `subjects`, in file
/// order. Throws std::invalid_argument naming a subject that has no sequence.
SkeletonDataset SelectSubjects(const SkeletonDataset& data,
                               const std::vector<std::string>& subjects);

/// Returns the column index (joint index) of each name in `names` within
/// `joint_names`. Throws std::invalid_argument naming the first unknown joint
/// and listing the available ones.
std::vector<int> JointIndices(const std::vector<std::string>& joint_names,
                              const std::vector<std::string>& names);

/// A sequence resampled to a uniform rate and restricted to the model joints.
struct Track {
  std::string sequence_id;
  std::string subject;
  std::string action;
  Eigen::MatrixXd positions;  ///< (n, 3 J_model) metres, frame S, uniform rate.
  /// (n, J_model) or empty: SkeletonSequence::reaching of the model joints,
  /// taken from the recorded frame nearest each resampled row.
  Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic> reaching;
  /// (n) or empty: SkeletonSequence::frame_actions at the nearest recorded frame.
  std::vector<std::string> frame_actions;
};

/// The action of row `row` of `track`: frame_actions[row] when the track has
/// frame actions, else its label. Requires 0 <= row < rows when it has them.
const std::string& ActionAt(const Track& track, int row);

/// Resamples `sequence` to `rate` (Hz) on the grid t0, t0 + 1/rate, ... (t0 =
/// first sample time) by linear interpolation between neighbouring recorded
/// frames, keeping only the joints `joint_index` (indices into the dataset's
/// joint list, in that order). Frames in which any of these joints was not
/// detected (see JointDetected()) are dropped first. Gaps up to `max_gap` seconds are
/// bridged by the interpolation; a longer gap splits the sequence into
/// separate tracks (a track never interpolates across such a gap).
/// Requires rate > 0 and max_gap > 0 (throws std::invalid_argument otherwise).
/// A sequence without any frame in which all joints were detected yields no track.
/// Reaching flags and frame actions, when the sequence has them (n rows, one
/// column per data joint; n labels; otherwise std::invalid_argument), follow
/// the nearest recorded frame.
std::vector<Track> ResampleSequence(const SkeletonSequence& sequence,
                                    const std::vector<int>& joint_index,
                                    double rate, double max_gap);

}  // namespace iplan::intent

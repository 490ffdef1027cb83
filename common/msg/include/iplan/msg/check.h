// Boundary checks for received messages. Every message that enters a service
// passes Check(): oversized sequences and strings, non-finite numbers,
// inconsistent sizes and out-of-range enumerations are reported with the
// field path, so the framework can reject, count and log them instead of
// letting them reach the algorithms.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <type_traits>

#include "iplan/msg/types.h"
#include "iplan/msg/visit.h"

namespace iplan::msg {

/// Size limits of received messages, stated once here. The IDL sequences and
/// strings are unbounded, so without them one message (a skeleton of 20,000
/// joints) holds a service for seconds; Check() tests them first, before any
/// per-element work, so the work per accepted message is bounded. Each limit
/// is far above what the cell's producers send and below what would stall a
/// consumer. A new message type with sequences or strings adds its constants
/// here and a CheckSizes overload below.
struct Limits {
  // Strings, in characters (bytes).
  static constexpr std::size_t kName = 256;  ///< identifiers: joint/link/action names, frame_id, task_name, source, keys
  /// Free text: reason, status, diagnostic message and value. Longer than a
  /// name because producers join causes (the supervisor's stop reason lists
  /// every failing input); refusing a protective stop for its wording would
  /// defeat the check.
  static constexpr std::size_t kText = 4096;

  // HumanSkeleton.
  static constexpr std::size_t kSkeletonJoints = 128;  ///< real trackers give 1-33

  // Robot joints: JointState, JointTrajectory, TaskCommand goal/retreat positions.
  static constexpr std::size_t kRobotJoints = 64;       ///< names and values per state or point
  static constexpr std::size_t kTrajectoryPoints = 2000;  ///< 200 s at 0.1 s, 20 s at 100 Hz; also CollisionRisk waypoint_bounds

  // ActionBelief and HumanPrediction.
  static constexpr std::size_t kActions = 32;
  static constexpr std::size_t kPredictionSteps = 200;   ///< num_steps
  static constexpr std::size_t kPredictionJoints = 128;  ///< joint_names
  /// Gaussians in one prediction, actions x num_steps x joint_names (96 B
  /// each, 6 MiB): 8 actions of 200 steps of a 33-joint body fit.
  static constexpr std::size_t kPredictionGaussians = 65536;

  // PointCloud2.
  static constexpr std::size_t kCloudPoints = 640 * 480 * 4;  ///< width x height: four VGA depth images
  static constexpr std::size_t kCloudPointStep = 256;         ///< bytes per point
  static constexpr std::size_t kCloudFields = 32;
  static constexpr std::size_t kCloudBytes = std::size_t{64} << 20;  ///< data, 64 MiB

  // Image (a depth camera's): the same pixel limit as a cloud's points.
  static constexpr std::size_t kImageBytes = std::size_t{64} << 20;  ///< data, 64 MiB
  // CameraInfo: ROS's models have 4 (equidistant), 5 (plumb_bob) or 8
  // (rational_polynomial) coefficients.
  static constexpr std::size_t kDistortionCoefficients = 32;  ///< d

  // ObstacleArray and HumanPoints.
  static constexpr std::size_t kObstacles = 256;        ///< boxes per array
  static constexpr std::size_t kHumanPoints = 65536;    ///< a person on a 1 cm grid has ~20,000
  static constexpr std::size_t kPointMotions = 1024;    ///< HumanPoints motions: a person has ~10 tracked parts

  // DiagnosticArray.
  static constexpr std::size_t kDiagnosticStatuses = 64;   ///< status entries per array
  static constexpr std::size_t kDiagnosticValues = 256;    ///< values per status (a node sends ~5 per topic)

  // TFMessage.
  static constexpr std::size_t kTransforms = 256;  ///< transforms per message (a robot's tree has ~20)
};

/// True when the type has a std_msgs Header named `header`.
template <class T, class = void>
struct HasHeader : std::false_type {};
template <class T>
struct HasHeader<T, std::void_t<decltype(std::declval<const T&>().header.stamp)>>
    : std::true_type {};

/// The Limits of each type: sequence lengths and string lengths, tested in
/// time independent of the message's size (or linear in an already bounded
/// size), before anything walks the elements. nullopt when within the limits.
/// A type without an overload of its own has only its header checked.
std::optional<std::string> CheckSizes(const Header& m);
std::optional<std::string> CheckSizes(const HumanSkeleton& m);
std::optional<std::string> CheckSizes(const ActionBelief& m);
std::optional<std::string> CheckSizes(const HumanPrediction& m);
std::optional<std::string> CheckSizes(const JointState& m);
std::optional<std::string> CheckSizes(const JointTrajectory& m);
std::optional<std::string> CheckSizes(const PointCloud2& m);
std::optional<std::string> CheckSizes(const Image& m);
std::optional<std::string> CheckSizes(const CameraInfo& m);
std::optional<std::string> CheckSizes(const ObstacleArray& m);
std::optional<std::string> CheckSizes(const HumanPoints& m);
std::optional<std::string> CheckSizes(const TaskCommand& m);
std::optional<std::string> CheckSizes(const TaskOutcome& m);
std::optional<std::string> CheckSizes(const PlanStatus& m);
std::optional<std::string> CheckSizes(const CollisionRisk& m);
std::optional<std::string> CheckSizes(const SafetyPermit& m);
std::optional<std::string> CheckSizes(const DiagnosticArray& m);
std::optional<std::string> CheckSizes(const TFMessage& m);
template <class T>
std::optional<std::string> CheckSizes(const T& m) {
  if constexpr (HasHeader<T>::value) {
    return CheckSizes(m.header);
  } else {
    return std::nullopt;
  }
}

/// Type-specific consistency rules (sizes, ranges). nullopt when consistent.
/// Types without rules of their own are consistent.
std::optional<std::string> CheckSemantics(const HumanSkeleton& m);
std::optional<std::string> CheckSemantics(const ActionBelief& m);
std::optional<std::string> CheckSemantics(const HumanPrediction& m);
std::optional<std::string> CheckSemantics(const JointState& m);
std::optional<std::string> CheckSemantics(const JointTrajectory& m);
std::optional<std::string> CheckSemantics(const PointCloud2& m);
std::optional<std::string> CheckSemantics(const Image& m);
std::optional<std::string> CheckSemantics(const CameraInfo& m);
std::optional<std::string> CheckSemantics(const ObstacleArray& m);
std::optional<std::string> CheckSemantics(const HumanPoints& m);
std::optional<std::string> CheckSemantics(const TaskCommand& m);
std::optional<std::string> CheckSemantics(const TaskOutcome& m);
std::optional<std::string> CheckSemantics(const PlanStatus& m);
std::optional<std::string> CheckSemantics(const CollisionRisk& m);
std::optional<std::string> CheckSemantics(const SafetyPermit& m);
std::optional<std::string> CheckSemantics(const DiagnosticArray& m);
std::optional<std::string> CheckSemantics(const Header& m);
template <class T>
std::optional<std::string> CheckSemantics(const T&) {
  return std::nullopt;
}

/// Why `m` must be rejected ("joints has 20000 entries, limit 128",
/// "non-finite number at joints[3].position.x", "position has 6 entries for
/// 7 names"), or nullopt when it is acceptable. Sizes come first: the later
/// checks walk every element. Thread-safe; allocates only for the returned
/// text.
template <class T>
std::optional<std::string> Check(const T& m) {
  if (auto e = CheckSizes(m)) return e;
  if (auto where = FindNonFinite(m)) return "non-finite number at " + *where;
  return CheckSemantics(m);
}

}  // namespace iplan::msg

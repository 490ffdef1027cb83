// Boundary checks for received messages. Every message that enters a service
// passes Check(): non-finite numbers, inconsistent sizes and out-of-range
// enumerations are reported with the field path, so the framework can reject,
// count and log them instead of letting them reach the algorithms.
#pragma once

#include <optional>
#include <string>

#include "iplan/msg/types.h"
#include "iplan/msg/visit.h"

namespace iplan::msg {

/// Type-specific consistency rules (sizes, ranges). nullopt when consistent.
/// Types without rules of their own are consistent.
std::optional<std::string> CheckSemantics(const HumanSkeleton& m);
std::optional<std::string> CheckSemantics(const ActionBelief& m);
std::optional<std::string> CheckSemantics(const HumanPrediction& m);
std::optional<std::string> CheckSemantics(const JointState& m);
std::optional<std::string> CheckSemantics(const JointTrajectory& m);
std::optional<std::string> CheckSemantics(const PointCloud2& m);
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

/// Why `m` must be rejected ("non-finite number at joints[3].position.x",
/// "position has 6 entries for 7 names"), or nullopt when it is acceptable.
/// Thread-safe; allocates only for the returned text.
template <class T>
std::optional<std::string> Check(const T& m) {
  if (auto where = FindNonFinite(m)) return "non-finite number at " + *where;
  return CheckSemantics(m);
}

/// True when the type has a std_msgs Header named `header`.
template <class T, class = void>
struct HasHeader : std::false_type {};
template <class T>
struct HasHeader<T, std::void_t<decltype(std::declval<const T&>().header.stamp)>>
    : std::true_type {};

}  // namespace iplan::msg

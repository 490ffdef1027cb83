// Self-collision of an arm by its collision spheres, and the link pairs not
// worth checking, found by sampling as MoveIt's setup assistant does:
// adjacent links (joined by a joint, fixed frames without geometry between
// them skipped), pairs that touch in (almost) every sampled configuration,
// and pairs that never come within a margin of each other. Frames: the
// robot's world frame W; distances in m. No DDS types.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "iplan/collision/robot_model.h"

namespace iplan::collision {

struct SelfCollisionParams {
  int samples = 2000;             ///< configurations drawn uniformly in the limits (continuous: [-pi, pi])
  std::uint64_t seed = 1;         ///< of the draws
  double never_margin = 0.02;     ///< m; a pair never closer than this in the samples is skipped
  double always_fraction = 0.95;  ///< a pair touching in at least this fraction of samples is skipped
  /// "" when valid, else the reason.
  std::string Validate() const;
};

/// Why a link pair is not checked.
enum class SkipReason { kAdjacent, kAlways, kNever };
const char* ToString(SkipReason r);

struct LinkPair {
  int link_a = -1, link_b = -1;  ///< link indices, link_a < link_b; both carry spheres
  SkipReason reason = SkipReason::kNever;
  double min_distance = 0.0;     ///< m, smallest sphere surface distance over the samples
};

struct SelfCollisionModel {
  std::vector<LinkPair> skipped;                 ///< pairs not checked, with their reason
  std::vector<std::pair<int, int>> checked;      ///< link pairs that are checked
  /// Sphere index pairs of the checked link pairs (what SelfDistance loops over).
  std::vector<std::pair<int, int>> sphere_pairs;
};

/// Samples `model` (deterministic for a seed). @throws std::invalid_argument
/// on invalid params. Allocates; about samples x (sphere pairs) distances.
SelfCollisionModel ComputeSelfCollision(const RobotModel& model, const SelfCollisionParams& params = {});

/// Smallest surface distance (m; negative: overlap) between spheres of the
/// checked pairs at the poses in `data` (after CalcForwardKinematics); +inf
/// when nothing is checked. Thread-safe; does not allocate.
double SelfDistance(const RobotModel& model, const SelfCollisionModel& self, const RobotData& data);

}  // namespace iplan::collision

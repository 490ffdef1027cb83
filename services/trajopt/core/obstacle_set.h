// The unknown obstacles the planner keeps clear of (issue 18): the boxes of
// the newest /iplan/obstacles arrays, without DDS types.
//
// Each array is the whole set the cloud stage sees in one cloud. A box
// missing from later arrays (occluded for a frame, the cloud stage busy) is
// kept until it has not been seen for `timeout`, then removed. A change of
// the set (a box added, moved or grown, or removed) is reported so the
// service replans at once instead of at its next tick.
//
// Frames and units: boxes axis-aligned in the world frame W (m); times ns
// since the epoch. Not thread-safe (one owner).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/cell/obstacle_box.h"
#include "iplan/collision/scene.h"

namespace iplan::trajopt {

/// One sensed box B in W (the cloud service's; id, pose and size are used).
using cell::ObstacleBox;

class ObstacleSet {
 public:
  /// timeout: s a box stays after it was last seen, > 0. min_half_extent:
  /// m, thinner boxes are thickened to it (a flat box still has a face the
  /// planner's distance sees), > 0. Throws std::invalid_argument.
  explicit ObstacleSet(double timeout = 2.0, double min_half_extent = 0.005);

  /// The array of one cloud (stamp_ns). Returns why it was refused (a
  /// repeated id, a non-finite or negative size, an orientation that is not
  /// a unit quaternion), else nullopt; *changed (may be null) tells whether
  /// the set changed: a new id, or a box that moved, changed size or turned
  /// (its angle times its half diagonal) by more than `tolerance` (m).
  std::optional<std::string> Update(int64_t stamp_ns, const std::vector<ObstacleBox>& boxes, bool* changed,
                                    double tolerance = 0.01);
  /// Removes boxes not seen for `timeout` at now_ns. Returns true when any was removed.
  bool Expire(int64_t now_ns);

  /// The current boxes as scene objects ("obstacle <id>"), in id order.
  std::vector<collision::SceneObject> SceneObjects() const;
  std::size_t size() const { return boxes_.size(); }

 private:
  struct Seen {
    ObstacleBox box;
    int64_t last_seen_ns = 0;
  };
  double timeout_, min_half_extent_;
  std::map<uint32_t, Seen> boxes_;
};

}  // namespace iplan::trajopt

// Tracking the depth camera's clusters over frames, to tell static unknown
// objects (a box left on the table) from moving ones (a person): a cluster
// whose centroid stays within `static_motion` of where it settled for
// `static_frames` frames is static; one that moves, or one as large as a
// person, is human. A static one seen only in part (its visible box within
// its settled box grown by `static_motion`: the arm in front of it) stays
// static with its settled box, and so does every piece of it when the arm
// splits it in two. A static obstacle's box is the running mean
// of its upright oriented boxes (z along W's z, the yaw that gives the
// smallest footprint), so a rotated bin is as large as it is. Pure
// algorithm, no DDS types.
//
// Frame: the cell frame W (`world`), metres; stamps in ns (wall clock).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/core/name_value.h"

namespace iplan::cloud_service {

struct TrackerParams {
  int static_frames = 10;        ///< frames a cluster must stay put to become a static obstacle
  double static_motion = 0.03;   ///< m the centroid may wander from where it settled and still be "put"
  double match_distance = 0.15;  ///< m, farthest centroid-to-centroid match between frames
  int lost_frames = 15;          ///< frames a track outlives its last sighting
  double person_extent = 0.5;    ///< m; a cluster with an edge this long is a person at once
  bool pending_as_human = true;  ///< clusters not yet classified count as human (the cautious choice)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(static_frames, "frames a cluster must stay put to become a static obstacle"));
    a->Visit(IPLAN_NVP(static_motion, "m the centroid may wander and still be put"));
    a->Visit(IPLAN_NVP(match_distance, "m, farthest centroid match between frames"));
    a->Visit(IPLAN_NVP(lost_frames, "frames a track outlives its last sighting"));
    a->Visit(IPLAN_NVP(person_extent, "m; a cluster with an edge this long is a person at once"));
    a->Visit(IPLAN_NVP(pending_as_human, "clusters not yet classified count as human"));
  }
  /// Empty when valid, else the first problem.
  std::string Validate() const;
};

/// A box B upright in W: its z axis along W's z, turned by `yaw` about it.
struct UprightBox {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();        ///< m, p_WB
  double yaw = 0;                                          ///< rad, about W's z
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  ///< m along B's x, y, z, >= 0
};

/// One cluster of one frame in W.
struct ClusterObservation {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< m, mean of the points
  Eigen::Vector3d box_min = Eigen::Vector3d::Zero();   ///< m, axis-aligned box around the points
  Eigen::Vector3d box_max = Eigen::Vector3d::Zero();   ///< m
  UprightBox box;                                      ///< the upright box of least footprint around the points
  int points = 0;
};

/// The running mean of upright boxes: `count` boxes so far in `mean`, then
/// `next`. A box is the same box turned by a multiple of 90 degrees with
/// its x and y extents swapped, so `next` is first turned to within 45
/// degrees of the mean's yaw.
void AddToMean(const UprightBox& next, int count, UprightBox* mean);

enum class TrackClass { kPending, kStatic, kHuman };

struct Track {
  uint32_t id = 0;  ///< >= 1, never reused
  TrackClass cls = TrackClass::kPending;
  ClusterObservation last;             ///< the latest sighting
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();  ///< m, where the centroid settled
  Eigen::Vector3d mean_min = Eigen::Vector3d::Zero();  ///< m, axis-aligned box averaged since it settled
  Eigen::Vector3d mean_max = Eigen::Vector3d::Zero();
  UprightBox mean_box;       ///< the upright box averaged since it settled
  int still = 0;             ///< frames since it settled at `anchor`
  int unseen = 0;            ///< frames since the last sighting
  int64_t first_seen_ns = 0;
};

class ClusterTracker {
 public:
  /// Throws std::invalid_argument when params.Validate() fails.
  explicit ClusterTracker(const TrackerParams& params);

  /// One frame: matches the observations to the tracks (nearest centroids
  /// first, within match_distance); an observation left over that lies in a
  /// static track's settled box is another piece of that obstacle (several
  /// observations may then share its track); starts tracks for the rest,
  /// ages and drops unseen ones. Returns, per observation, the index into tracks()
  /// of its track (valid until the next Update).
  std::vector<int> Update(const std::vector<ClusterObservation>& clusters, int64_t stamp_ns);

  const std::vector<Track>& tracks() const { return tracks_; }
  /// True when the observation's track counts as human this frame.
  bool IsHuman(const Track& t) const {
    return t.cls == TrackClass::kHuman || (t.cls == TrackClass::kPending && params_.pending_as_human);
  }

 private:
  void Observe(Track* t, const ClusterObservation& o) const;
  /// True when `t` is static and `o`'s box lies within its settled box grown
  /// by static_motion: `o` is (a piece of) that obstacle seen in part.
  bool InSettledBox(const Track& t, const ClusterObservation& o) const;

  TrackerParams params_;
  std::vector<Track> tracks_;
  uint32_t next_id_ = 1;
};

}  // namespace iplan::cloud_service

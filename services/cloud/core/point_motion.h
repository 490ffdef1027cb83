// The velocity of the human points (issue 29): the points the cloud stage
// takes for people are divided into parts, each followed over frames by a
// constant-velocity Kalman filter on its centroid, so that every point
// carries the measured velocity (and its uncertainty) of the part it is in.
// Parts, not whole clusters: a person standing at the table whose hand
// reaches towards the robot is one cluster whose centroid hardly moves, while
// the hand's part moves at the hand's speed.
//
// Per frame (stamps in ns, wall clock; positions in the cell frame W, m):
//  1. every part is predicted to the frame's stamp (continuous white-noise
//     acceleration of spectral density acceleration_density: the velocity
//     variance grows by it per second);
//  2. its measurement: the centroid m of the points within part_radius of
//     its predicted position, less the offset o = m' - x the part had from
//     the centroid of its ball in the frame before. The ball moves with the
//     part, not with its neighbours, so a part does not drift while other
//     parts come and go (a Voronoi cell's centroid would), and a still
//     surface gives the same m frame after frame; the frame-to-frame
//     displacement of the ball's content is what is measured. The ball is
//     re-centred on the measured position up to three times (mean shift
//     with the offset), so a part whose prediction lags still finds the
//     displaced points;
//  3. a part with min_points or more in its ball is measured
//     (measurement_sigma per axis). The centroid also moves when the
//     visible share of the ball changes (the arm appears from behind the
//     body, half the part is hidden), not only when the part does. Two
//     guards: the measurement's standard deviation grows by
//     visibility_sigma times the relative change of the ball's point count
//     since the last frame, |n - n'| / max(n, n') (a part that loses half
//     its points moves its centroid by about half its radius); and an
//     innovation whose normalised square still exceeds `gate` is
//     down-weighted to it (the innovation covariance scaled up). So a jump
//     of the visible part moves the estimate by a small step, while a
//     lasting motion (the ball keeps its points) comes through within a few
//     frames;
//  4. each point belongs to the part whose position is nearest, if within
//     part_radius; points no part is that near seed new parts (greedily,
//     part_radius around the first point left): at rest with
//     initial_speed_sigma per axis, or, within two part radii of a tracked
//     part (the same body, its visible region grown: an arm reaching out,
//     a hand coming out from behind the robot), at that part's velocity
//     with its covariance grown by neighbour_speed_sigma per axis (what one
//     part of a body may move relative to the next), trusted as long as its
//     velocity std stays within the neighbour's limit so grown (a part
//     coming out from behind the arm is tracked from its first frame, not
//     judged at the ISO speed until its own filter has converged);
//  5. parts unmeasured for more than lost_frames frames are dropped; of two
//     parts closer than merge_distance the younger is dropped;
//  6. a part that is not tracked (too few of its points seen this frame,
//     its variance grown past the limit) but lies within two part radii of
//     a tracked one is judged as a part seeded there would be: at that
//     part's velocity with neighbour_speed_sigma more uncertainty
//     (VelocityOf); only points with no tracked part near them are left to
//     the ISO default speed.
// Pure algorithm, no DDS types. Not thread-safe; allocates.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/core/name_value.h"

namespace iplan::cloud_service {

struct MotionParams {
  double part_radius = 0.2;           ///< m; a point joins the nearest part within this
  int min_points = 5;                 ///< points a part needs in a frame to be measured
  double measurement_sigma = 0.005;   ///< m per axis, the centroid's measurement noise (motion_eval: cross-validated)
  double acceleration_density = 0.9;  ///< m^2/s^3 per axis, white-noise acceleration (motion_eval: cross-validated)
  double initial_speed_sigma = 1.0;   ///< m/s per axis, velocity uncertainty of a new part
  double tracked_speed_sigma = 0.5;   ///< m/s; largest velocity std of a tracked part
  double neighbour_speed_sigma = 0.4; ///< m/s per axis a new part next to a tracked one may move relative to it
  double visibility_sigma = 0.2;      ///< m per unit relative change of a ball's point count, added to measurement_sigma
  double gate = 11.34;                ///< normalised innovation square above which a measurement is down-weighted (chi^2, 3 dof, 99 %)
  int lost_frames = 3;                ///< frames a part outlives its last measurement
  double merge_distance = 0.08;       ///< m; of two parts closer than this the younger is dropped
  double max_gap = 0.5;               ///< s; a longer gap between frames starts afresh

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(part_radius, "m; a point joins the nearest part whose predicted centre is within this, > 0"));
    a->Visit(IPLAN_NVP(min_points, "points a part needs in a frame to be measured, >= 1"));
    a->Visit(IPLAN_NVP(measurement_sigma, "m per axis, noise of a part's centroid, > 0"));
    a->Visit(IPLAN_NVP(acceleration_density, "m^2/s^3 per axis, spectral density of the white-noise acceleration (velocity variance per second), > 0"));
    a->Visit(IPLAN_NVP(initial_speed_sigma, "m/s per axis, velocity uncertainty of a new part, > 0"));
    a->Visit(IPLAN_NVP(tracked_speed_sigma, "m/s; a part's velocity is trusted once its largest std is at most this, > 0"));
    a->Visit(IPLAN_NVP(neighbour_speed_sigma, "m/s per axis; a new part next to a tracked one starts from its velocity with this much more uncertainty, >= 0"));
    a->Visit(IPLAN_NVP(visibility_sigma, "m; a centroid's std grows by this times the relative change of its ball's point count, >= 0"));
    a->Visit(IPLAN_NVP(gate, "normalised innovation square above which a centroid is down-weighted, > 0"));
    a->Visit(IPLAN_NVP(lost_frames, "frames a part outlives its last measurement, >= 0"));
    a->Visit(IPLAN_NVP(merge_distance, "m; of two parts closer than this the younger is dropped, >= 0"));
    a->Visit(IPLAN_NVP(max_gap, "s; a longer gap between frames drops every part, > 0"));
  }
  /// Empty when valid, else the first problem.
  std::string Validate() const;
};

/// One part: the Kalman state [p; v] (m, m/s, W) and its covariance.
struct MotionPart {
  uint32_t id = 0;  ///< >= 1, never reused
  Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 6> P = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  ///< m, centroid of its ball minus its position, last frame
  int ball_points = 0;  ///< points in its ball, last frame
  int measured = 0;  ///< measurements so far
  int unseen = 0;    ///< frames since the last measurement
  int points = 0;    ///< points that belong to it in the latest frame
  /// Seeded next to a tracked part, from its velocity: trusted up to the
  /// neighbour's limit grown by the relative motion allowed (Tracked).
  bool from_neighbour = false;

  Eigen::Vector3d centre() const { return x.head<3>(); }
  Eigen::Vector3d velocity() const { return x.tail<3>(); }
  Eigen::Matrix3d velocity_covariance() const { return P.bottomRightCorner<3, 3>(); }
};

/// The velocity a part's points are judged at (m/s, W) and its covariance
/// ((m/s)^2).
struct PartVelocity {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

class MotionTracker {
 public:
  /// Throws std::invalid_argument when params.Validate() fails.
  explicit MotionTracker(const MotionParams& params);

  /// One frame of human points (m, W). Returns, per point, the index into
  /// parts() of the part it joined (valid until the next call), -1 in the
  /// one case that none is left for it (its part was dropped, and every other).
  std::vector<int> Update(const std::vector<Eigen::Vector3d>& p_W, int64_t stamp_ns);
  const std::vector<MotionPart>& parts() const { return parts_; }
  /// True when the part's velocity may be trusted: measured at least twice
  /// (or seeded from a tracked neighbour) and its largest velocity std at
  /// most tracked_speed_sigma, or, for a part seeded from a neighbour, at
  /// most sqrt(tracked_speed_sigma^2 + neighbour_speed_sigma^2) (the
  /// neighbour's limit and the relative motion it was seeded with).
  bool Tracked(const MotionPart& part) const;
  /// What the points of parts()[k] are judged at: its own velocity and
  /// covariance when Tracked; otherwise, within two part radii of a tracked
  /// part (the nearest), that part's velocity with its covariance grown by
  /// neighbour_speed_sigma per axis, as a part is seeded there (a part of
  /// the body whose own filter has lost track for a frame: too few of its
  /// points seen, its variance grown past the limit); otherwise nullopt
  /// (nothing tracked near it: the ISO default speed).
  std::optional<PartVelocity> VelocityOf(std::size_t k) const;

 private:
  void Predict(double dt);
  void Measure(MotionPart* part, const std::vector<Eigen::Vector3d>& p_W) const;
  /// The centroid of the points within part_radius of `centre` and their
  /// number; false when fewer than min_points are.
  bool BallCentroid(const std::vector<Eigen::Vector3d>& p_W, const Eigen::Vector3d& centre, Eigen::Vector3d* m,
                    int* n) const;
  void Seed(const std::vector<Eigen::Vector3d>& p_W, std::vector<int>* part_of);
  /// The tracked part nearest `centre` within two part radii, or null.
  const MotionPart* NearestTracked(const Eigen::Vector3d& centre) const;
  /// A part next to `neighbour`: its velocity, its covariance grown by
  /// neighbour_speed_sigma per axis (what one part of a body may move
  /// relative to the next).
  PartVelocity NextTo(const MotionPart& neighbour) const;
  void Prune(std::vector<int>* part_of);

  MotionParams params_;
  std::vector<MotionPart> parts_;
  int64_t last_stamp_ns_ = 0;
  uint32_t next_id_ = 1;
};

}  // namespace iplan::cloud_service

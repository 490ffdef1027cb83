// The collision bound of METHOD.md section 4 against a person seen only as
// points (a depth camera's cloud, /iplan/human/points): each point l is a
// small sphere of radius r_p (half the voxel size) whose centre is
// N(mu_l, Sigma_l), Sigma_l the sensor's noise at that depth, and
//
//   P_i = max over (robot sphere k, point l) of PairBound(B_k(q_i), C_l)
//
// per waypoint i, with the pair bound of bound.h (no mixture: the points are
// where the person is seen now). Culling: the points are grouped into blocks
// (a grid of block_size, each block a ball around its means); a pair whose
// centre distance is at least R + T, T = sqrt(2 s_max (log_peak_max +
// log V(R) - log negligible)) with s_max and log_peak_max the block's largest
// covariance eigenvalue and density peak, has a bound below `negligible`
// (the density outside that distance is below negligible / V(R) everywhere
// in the ball), and a block whose ball is that far from a robot sphere is
// skipped whole. A pair (or block) whose upper bound V(R) exp(log_peak -
// (dist - R)^2 / 2 s_max) cannot exceed the waypoint's best so far is
// skipped as well, and a waypoint stops at a bound of 1, so the maximum and
// its argmax (the first pair attaining it) are those of all pairs.
// When every pair of a waypoint was culled its bound is
// reported as `negligible` (exact = false), so the result is always an upper
// bound and equals the all-pairs maximum whenever that is above negligible.
//
// Frames and units: world frame W, m, m^2. No DDS types.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/collision/bound.h"
#include "iplan/collision/trajectory_bound.h"

namespace iplan::collision {

/// The sensed points, factorised once per cloud and grouped into blocks.
/// Const methods are thread-safe.
class GaussianPoints {
 public:
  /// A ball around the means of points [begin, end) (storage order).
  struct Block {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< m, W
    double radius = 0.0;          ///< m, max ||mu_l - centre||
    double max_eigenvalue = 0.0;  ///< m^2, largest covariance eigenvalue in the block
    double max_log_peak = 0.0;    ///< largest log density peak in the block
    int begin = 0, end = 0;
  };

  GaussianPoints() = default;
  /// means 3 x n (m, W), covariances n (m^2, symmetric), radius r_p (m, >= 0),
  /// block_size (m, > 0). Returns why the points were refused (a covariance
  /// that is not positive definite, names the point; sizes; radius), leaving
  /// the object empty; nullopt when accepted. Allocates.
  std::optional<std::string> Set(const Eigen::Matrix3Xd& means, const std::vector<Eigen::Matrix3d>& covariances,
                                 double radius, double block_size = 0.1);

  int size() const { return static_cast<int>(points_.size()); }
  bool empty() const { return points_.empty(); }
  double radius() const { return radius_; }
  /// Point i in storage order (grouped by block) and its index in the input.
  const FactorizedGaussian& point(int i) const { return points_[static_cast<std::size_t>(i)]; }
  int input_index(int i) const { return input_index_[static_cast<std::size_t>(i)]; }
  const std::vector<Block>& blocks() const { return blocks_; }

 private:
  double radius_ = 0.0;
  std::vector<FactorizedGaussian> points_;
  std::vector<int> input_index_;
  std::vector<Block> blocks_;
};

/// Tuning of EvaluatePointsBound; the result is an upper bound for any value.
struct PointsBoundParams {
  /// Pairs that cannot exceed this are culled (file comment), > 0.
  double negligible = 1e-9;
};

/// P_i per waypoint of `trajectory` (its `steps` only count the waypoints)
/// into *out (resized to trajectory.num_waypoints()): bound, exact, the
/// robot sphere and link, human_sphere = the point's input index (segment and
/// action -1), pairs evaluated and skipped (culled or unable to exceed the
/// best; pairs after a bound of 1 are not counted). Empty points give bound 0.
/// Does not allocate when *out has the right size. Thread-safe.
void EvaluatePointsBound(const GaussianPoints& points, const RobotSpheresTrajectory& trajectory,
                         const PointsBoundParams& params, std::vector<WaypointBound>* out);

/// The same over all pairs without culling: the reference for tests and the
/// benchmark.
void EvaluatePointsBoundAllPairs(const GaussianPoints& points, const RobotSpheresTrajectory& trajectory,
                                 std::vector<WaypointBound>* out);

}  // namespace iplan::collision

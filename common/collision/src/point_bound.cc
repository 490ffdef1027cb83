#include "iplan/collision/point_bound.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace iplan::collision {
namespace {

// Distance T beyond R at which the block's density, over the whole ball of
// radius R, is below negligible / V(R) (see point_bound.h); 0 when even the
// peak is.
double CullDistance(const GaussianPoints::Block& b, double log_volume, double log_negligible) {
  const double a = b.max_log_peak + log_volume - log_negligible;
  return a > 0.0 ? std::sqrt(2.0 * b.max_eigenvalue * a) : 0.0;
}

void Record(double log_bound, int k, int point, const RobotSpheresTrajectory& t, const GaussianPoints& pts,
            WaypointBound* wb) {
  const double bound = std::min(1.0, std::exp(log_bound));
  if (wb->robot_sphere < 0 || bound > wb->bound) {
    wb->bound = bound;
    wb->robot_sphere = k;
    wb->robot_link = t.links.empty() ? -1 : t.links[static_cast<std::size_t>(k)];
    wb->human_sphere = pts.input_index(point);
  }
}

}  // namespace

std::optional<std::string> GaussianPoints::Set(const Eigen::Matrix3Xd& means,
                                               const std::vector<Eigen::Matrix3d>& covariances, double radius,
                                               double block_size) {
  points_.clear();
  input_index_.clear();
  blocks_.clear();
  radius_ = 0.0;
  const std::size_t n = static_cast<std::size_t>(means.cols());
  if (covariances.size() != n)
    return std::to_string(n) + " means but " + std::to_string(covariances.size()) + " covariances";
  if (!(radius >= 0.0) || !std::isfinite(radius)) return "point radius " + std::to_string(radius) + " is not >= 0";
  if (!(block_size > 0.0) || !std::isfinite(block_size)) return "block_size must be > 0";
  if (!means.allFinite()) return std::string("a point's mean is not finite");
  // Group by grid cell: sort the points by their cell's integer coordinates.
  std::vector<std::array<long long, 3>> cell(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      cell[i][static_cast<std::size_t>(a)] =
          static_cast<long long>(std::floor(means(a, static_cast<Eigen::Index>(i)) / block_size));
  input_index_.resize(n);
  std::iota(input_index_.begin(), input_index_.end(), 0);
  auto key = [&](int i) { return std::make_pair(cell[static_cast<std::size_t>(i)], i); };
  std::sort(input_index_.begin(), input_index_.end(), [&](int a, int b) { return key(a) < key(b); });
  points_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int src = input_index_[i];
    if (!FactorizeGaussian(means.col(src), covariances[static_cast<std::size_t>(src)], &points_[i])) {
      points_.clear();
      input_index_.clear();
      return "point " + std::to_string(src) + ": covariance is not positive definite";
    }
  }
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    Block b;
    b.begin = static_cast<int>(i);
    const auto& first = cell[static_cast<std::size_t>(input_index_[i])];
    while (j < n && cell[static_cast<std::size_t>(input_index_[j])] == first) {
      b.centre += points_[j].mean;
      ++j;
    }
    b.end = static_cast<int>(j);
    b.centre /= static_cast<double>(j - i);
    b.max_log_peak = -std::numeric_limits<double>::infinity();
    for (std::size_t l = i; l < j; ++l) {
      b.radius = std::max(b.radius, (points_[l].mean - b.centre).norm());
      b.max_eigenvalue = std::max(b.max_eigenvalue, points_[l].eigenvalues[2]);
      b.max_log_peak = std::max(b.max_log_peak, points_[l].log_peak_density);
    }
    blocks_.push_back(b);
    i = j;
  }
  radius_ = radius;
  return std::nullopt;
}

void EvaluatePointsBound(const GaussianPoints& points, const RobotSpheresTrajectory& t,
                         const PointsBoundParams& params, std::vector<WaypointBound>* out) {
  const int S = t.num_spheres(), W = t.num_waypoints();
  out->resize(static_cast<std::size_t>(W));
  const double log_negligible = std::log(params.negligible);
  for (int w = 0; w < W; ++w) {
    WaypointBound& wb = (*out)[static_cast<std::size_t>(w)];
    wb = WaypointBound{};
    bool culled = false;
    // A pair whose upper bound V(R) exp(log_peak - (dist - R)^2 / 2 s_max)
    // cannot exceed the best so far is skipped too (so the maximum and its
    // argmax, the first pair attaining it, are those of all pairs); a bound
    // of 1 cannot be exceeded at all.
    double best_log = -std::numeric_limits<double>::infinity();
    for (int k = 0; k < S && wb.bound < 1.0; ++k) {
      const Eigen::Vector3d b = t.centres.col(static_cast<Eigen::Index>(w) * S + k);
      const double R = t.radii[static_cast<std::size_t>(k)] + points.radius();
      if (!(R > 0.0)) continue;
      const double log_volume = std::log(BallVolume(R));
      for (const GaussianPoints::Block& blk : points.blocks()) {
        const double reach = R + CullDistance(blk, log_volume, log_negligible);
        const double block_gap = (b - blk.centre).norm() - blk.radius - R;
        if (block_gap + R >= reach) {
          wb.pairs_pruned += blk.end - blk.begin;
          culled = true;
          continue;
        }
        const double block_log_peak = log_volume + blk.max_log_peak, half_inv = 0.5 / blk.max_eigenvalue;
        if (block_gap > 0.0 && block_log_peak - block_gap * block_gap * half_inv <= best_log) {
          wb.pairs_pruned += blk.end - blk.begin;
          continue;
        }
        for (int l = blk.begin; l < blk.end; ++l) {
          const FactorizedGaussian& g = points.point(l);
          const double dist = (b - g.mean).norm();
          if (dist >= reach) {
            ++wb.pairs_pruned;
            culled = true;
            continue;
          }
          if (dist > R && block_log_peak - (dist - R) * (dist - R) * half_inv <= best_log) {
            ++wb.pairs_pruned;
            continue;
          }
          ++wb.pairs_evaluated;
          const double log_bound = EvaluatePairLogBound(g, b, R);
          if (log_bound > best_log) {
            best_log = log_bound;
            Record(log_bound, k, l, t, points, &wb);
          }
        }
      }
    }
    // Every culled pair is below negligible: so is the maximum when nothing
    // evaluated exceeds it.
    if (culled && wb.bound < params.negligible) {
      wb.bound = params.negligible;
      wb.exact = false;
    }
  }
}

void EvaluatePointsBoundAllPairs(const GaussianPoints& points, const RobotSpheresTrajectory& t,
                                 std::vector<WaypointBound>* out) {
  const int S = t.num_spheres(), W = t.num_waypoints();
  out->assign(static_cast<std::size_t>(W), WaypointBound{});
  for (int w = 0; w < W; ++w) {
    WaypointBound& wb = (*out)[static_cast<std::size_t>(w)];
    for (int k = 0; k < S; ++k) {
      const Eigen::Vector3d b = t.centres.col(static_cast<Eigen::Index>(w) * S + k);
      const double R = t.radii[static_cast<std::size_t>(k)] + points.radius();
      if (!(R > 0.0)) continue;
      for (int l = 0; l < points.size(); ++l) {
        ++wb.pairs_evaluated;
        Record(EvaluatePairLogBound(points.point(l), b, R), k, l, t, points, &wb);
      }
    }
  }
}

}  // namespace iplan::collision

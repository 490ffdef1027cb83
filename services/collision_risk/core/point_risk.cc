#include "point_risk.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace iplan::collision_risk {
namespace {

double LargestStd(const Eigen::Matrix3d& c) {
  const double l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(c, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  return std::sqrt(std::max(0.0, l));
}

}  // namespace

std::string PointsParams::Validate() const {
  if (!(horizon > 0)) return "human_points.horizon must be > 0";
  if (!(time_step > 0 && time_step <= horizon)) return "human_points.time_step must be in (0, horizon]";
  if (!(min_point_radius > 0)) return "human_points.min_point_radius must be > 0";
  if (!(block_size > 0)) return "human_points.block_size must be > 0";
  if (!(speed_sigmas >= 0 && std::isfinite(speed_sigmas))) return "human_points.speed_sigmas must be >= 0";
  if (!(motion_horizon >= 0 && std::isfinite(motion_horizon))) return "human_points.motion_horizon must be >= 0";
  return "";
}

PointsSeparation EvaluatePointsSeparation(const collision::GaussianPoints& points, const cell::HumanPoints& seen,
                                          const Eigen::Matrix3Xd& p_WS, const std::vector<double>& radii,
                                          const Eigen::Matrix3Xd& v_WS, const safety::SsmParams& s,
                                          double speed_sigmas) {
  PointsSeparation out;
  if (points.empty()) return out;
  out.any = true;
  // The largest v_h of each motion, and of each block's points.
  std::vector<double> motion_speed(seen.motions.size());
  for (std::size_t k = 0; k < seen.motions.size(); ++k) {
    const cell::PointMotion& m = seen.motions[k];
    motion_speed[k] = m.velocity.norm() + speed_sigmas * LargestStd(m.covariance);
  }
  auto speed_bound = [&](int input) {
    const int k = seen.MotionIndexOf(input);
    return k >= 0 ? motion_speed[static_cast<std::size_t>(k)] : s.default_human_speed;
  };
  std::vector<double> block_speed(points.blocks().size(), 0.0);
  for (std::size_t b = 0; b < points.blocks().size(); ++b) {
    const collision::GaussianPoints::Block& blk = points.blocks()[b];
    for (int l = blk.begin; l < blk.end; ++l) block_speed[b] = std::max(block_speed[b], speed_bound(points.input_index(l)));
  }
  const double v_r_max = v_WS.cols() > 0 ? v_WS.colwise().norm().maxCoeff() : 0.0;
  double best = std::numeric_limits<double>::infinity(), best_margin = best;
  for (Eigen::Index k = 0; k < p_WS.cols(); ++k) {
    const Eigen::Vector3d b = p_WS.col(k);
    const double r = radii[static_cast<std::size_t>(k)] + points.radius();
    const double v_k = s.directed ? v_WS.col(k).norm() : v_r_max;
    for (std::size_t bi = 0; bi < points.blocks().size(); ++bi) {
      const collision::GaussianPoints::Block& blk = points.blocks()[bi];
      const double lower = (b - blk.centre).norm() - blk.radius - r;
      const double sp_max = safety::ProtectiveSeparationDistance(s, block_speed[bi], v_k);
      const bool outside = lower - v_k * s.speed_reduction_time >= sp_max;  // every pair: scales 1, no violation
      if (outside && lower >= best && lower - sp_max >= best_margin) continue;
      for (int l = blk.begin; l < blk.end; ++l) {
        const int input = points.input_index(l);
        const cell::PointMotion* m = seen.MotionOf(input);
        const Eigen::Vector3d delta = b - points.point(l).mean;  // point -> robot
        const double centres = delta.norm();
        const double d = centres - r;
        const Eigen::Vector3d u = centres > 1e-9 ? Eigen::Vector3d(delta / centres) : Eigen::Vector3d::Zero();
        safety::SsmPair pair;
        if (s.directed) {
          // Coincident centres (u = 0) give S_p > 0 > d: a stop whatever the speeds.
          const Eigen::Vector3d v_h =
              m ? Eigen::Vector3d(m->velocity + speed_sigmas * std::sqrt(std::max(0.0, u.dot(m->covariance * u))) * u)
                : Eigen::Vector3d(s.default_human_speed * u);
          pair = safety::SsmPairRule(s, delta, r, v_h, v_WS.col(k));
        } else {
          pair.separation = d;
          pair.v_h = speed_bound(input);
          pair.v_r = v_r_max;
          pair.protective_separation = safety::ProtectiveSeparationDistance(s, pair.v_h, pair.v_r);
          pair.margin = d - pair.protective_separation;
          pair.stop_scale = safety::SpeedScaleFor(s, d, pair.v_h, pair.v_r);
          pair.slow_scale = safety::SpeedScaleFor(s, d - pair.v_r * s.speed_reduction_time, pair.v_h, pair.v_r);
        }
        out.slow_scale = std::min(out.slow_scale, pair.slow_scale);
        out.stop_scale = std::min(out.stop_scale, pair.stop_scale);
        if (d < best) {
          best = d;
          out.closest_sphere = static_cast<int>(k);
        }
        const double margin = pair.retreating ? 0.0 : pair.margin;
        if (margin < best_margin) {
          best_margin = margin;
          out.binding_separation = d;
          out.protective_separation = pair.protective_separation;
          out.human_speed = pair.v_h;
          out.robot_speed = pair.v_r;
          out.binding_sphere = static_cast<int>(k);
          out.binding_point = input;
          out.binding_tracked = m != nullptr;
          out.retreating = pair.retreating;
        }
      }
    }
  }
  out.min_separation = best;
  return out;
}

}  // namespace iplan::collision_risk

#include "point_risk.h"

#include <algorithm>
#include <limits>

namespace iplan::collision_risk {

std::string PointsParams::Validate() const {
  if (!(horizon > 0)) return "human_points.horizon must be > 0";
  if (!(time_step > 0 && time_step <= horizon)) return "human_points.time_step must be in (0, horizon]";
  if (!(min_point_radius > 0)) return "human_points.min_point_radius must be > 0";
  if (!(block_size > 0)) return "human_points.block_size must be > 0";
  return "";
}

PointsSeparation EvaluatePointsSeparation(const collision::GaussianPoints& points, const Eigen::Matrix3Xd& p_WS,
                                          const std::vector<double>& radii, const Eigen::Matrix3Xd& v_WS,
                                          const cell::SsmParams& s) {
  PointsSeparation out;
  if (points.empty()) return out;
  out.any = true;
  const double v_h = s.default_human_speed;  // a point has no measurable speed
  const double v_r_max = v_WS.cols() > 0 ? v_WS.colwise().norm().maxCoeff() : 0.0;
  double best = std::numeric_limits<double>::infinity(), best_margin = best;
  for (Eigen::Index k = 0; k < p_WS.cols(); ++k) {
    const Eigen::Vector3d b = p_WS.col(k);
    const double r = radii[static_cast<std::size_t>(k)] + points.radius();
    const double v_k = s.directed ? v_WS.col(k).norm() : v_r_max;
    const double sp_max = cell::ProtectiveSeparationDistance(s, v_h, v_k);
    for (const collision::GaussianPoints::Block& blk : points.blocks()) {
      const double lower = (b - blk.centre).norm() - blk.radius - r;
      if (lower >= best && lower - sp_max >= best_margin) continue;
      for (int l = blk.begin; l < blk.end; ++l) {
        const Eigen::Vector3d delta = b - points.point(l).mean;  // point -> robot
        const double centres = delta.norm();
        const double d = centres - r;
        double v_r = v_k;
        if (s.directed) {
          // Coincident centres (u = 0) give S_p > 0 > d: a stop whatever the speeds.
          const Eigen::Vector3d u = centres > 1e-9 ? Eigen::Vector3d(delta / centres) : Eigen::Vector3d::Zero();
          v_r = std::max(0.0, -v_WS.col(k).dot(u));
        }
        const double sp = cell::ProtectiveSeparationDistance(s, v_h, v_r);
        if (d < best) {
          best = d;
          out.closest_sphere = static_cast<int>(k);
        }
        if (d - sp < best_margin) {
          best_margin = d - sp;
          out.binding_separation = d;
          out.protective_separation = sp;
          out.human_speed = v_h;
          out.robot_speed = v_r;
          out.binding_sphere = static_cast<int>(k);
          out.binding_point = points.input_index(l);
        }
      }
    }
  }
  out.min_separation = best;
  return out;
}

}  // namespace iplan::collision_risk

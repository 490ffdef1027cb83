#include "services/trajopt/core/points_prediction.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include <Eigen/Eigenvalues>

namespace iplan::trajopt {
namespace {

constexpr double kMinPointRadius = 0.005;  // m
constexpr double kMinVariance = 1e-6;      // m^2, (1 mm)^2

// One coarse sphere: the points of one part in one grid cell.
struct Cell {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d noise = Eigen::Matrix3d::Zero();  // sum of the points' covariances
  std::vector<int> points;
  int motion = -1;
};

std::map<std::tuple<int, long, long, long>, Cell> Coarsen(const cell::HumanPoints& seen, double size) {
  std::map<std::tuple<int, long, long, long>, Cell> cells;
  for (int i = 0; i < seen.size(); ++i) {
    const Eigen::Vector3d p = seen.means.col(i);
    const int motion = seen.MotionIndexOf(i);
    const auto key = std::make_tuple(motion, std::lround(std::floor(p.x() / size)), std::lround(std::floor(p.y() / size)),
                                     std::lround(std::floor(p.z() / size)));
    Cell& c = cells[key];
    c.sum += p;
    c.noise += seen.covariances[static_cast<std::size_t>(i)];
    c.points.push_back(i);
    c.motion = motion;
  }
  return cells;
}

}  // namespace

std::string PointsPredictionParams::Validate() const {
  if (!(sphere_size > 0 && std::isfinite(sphere_size))) return "human_points.sphere_size must be > 0 m";
  if (!(time_step > 0 && std::isfinite(time_step))) return "human_points.time_step must be > 0 s";
  if (!(horizon >= time_step && std::isfinite(horizon))) return "human_points.horizon must be >= time_step";
  if (!(motion_horizon >= 0 && std::isfinite(motion_horizon))) return "human_points.motion_horizon must be >= 0 s";
  if (max_spheres < 1) return "human_points.max_spheres must be >= 1, got " + std::to_string(max_spheres);
  if (!(speed_sigmas >= 0 && std::isfinite(speed_sigmas))) return "human_points.speed_sigmas must be >= 0";
  return "";
}

std::optional<collision::HumanPrediction> BuildPointsPrediction(const PointsPredictionParams& params,
                                                                const cell::HumanPoints& seen,
                                                                const safety::SsmParams& ssm) {
  if (seen.size() == 0) return std::nullopt;
  double size = params.sphere_size;
  std::map<std::tuple<int, long, long, long>, Cell> cells = Coarsen(seen, size);
  while (static_cast<int>(cells.size()) > params.max_spheres) {
    size *= 2;
    cells = Coarsen(seen, size);
  }
  const double point_radius = std::max(kMinPointRadius, 0.5 * seen.voxel_size);
  std::vector<double> radii, allowances;
  std::vector<Eigen::Vector3d> centres;
  std::vector<Eigen::Matrix3d> noise;
  std::vector<const cell::PointMotion*> motions;
  for (const auto& [key, c] : cells) {
    const double n = static_cast<double>(c.points.size());
    const Eigen::Vector3d centre = c.sum / n;
    double r = 0;
    for (int i : c.points) r = std::max(r, (seen.means.col(i) - centre).norm());
    const cell::PointMotion* m =
        params.tracked_speeds && c.motion >= 0 ? &seen.motions[static_cast<std::size_t>(c.motion)] : nullptr;
    const double uncertain_speed =
        m ? params.speed_sigmas *
                std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m->covariance, Eigen::EigenvaluesOnly)
                                            .eigenvalues()
                                            .maxCoeff()))
          : ssm.default_human_speed;
    radii.push_back(r + point_radius);
    allowances.push_back(uncertain_speed);
    centres.push_back(centre);
    noise.push_back(c.noise / n + kMinVariance * Eigen::Matrix3d::Identity());
    motions.push_back(m);
  }
  const int steps = std::max(1, static_cast<int>(std::floor(params.horizon / params.time_step + 1e-9)));
  collision::HumanPrediction out(1, steps, radii);
  out.set_action_probability(0, 1.0);
  for (std::size_t l = 0; l < allowances.size(); ++l) out.set_speed_allowance(static_cast<int>(l), allowances[l]);
  for (int k = 0; k < steps; ++k) {
    const double t = (k + 1) * params.time_step;
    for (std::size_t l = 0; l < centres.size(); ++l) {
      Eigen::Vector3d mean = centres[l];
      Eigen::Matrix3d cov = noise[l];
      if (const cell::PointMotion* m = motions[l]) {
        mean += std::min(t, params.motion_horizon) * m->velocity;
        cov += t * t * m->covariance;
      }
      // Positive definite by construction (a PD noise plus a PSD growth).
      out.SetSphere(0, k, static_cast<int>(l), mean, cov);
    }
  }
  out.UpdateSummaries();
  return out;
}

}  // namespace iplan::trajopt

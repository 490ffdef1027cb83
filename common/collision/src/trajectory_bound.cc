#include "iplan/collision/trajectory_bound.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "check.h"
#include "secular_kernel.h"

namespace iplan::collision {

HumanPrediction::HumanPrediction(int num_actions, int num_steps,
                                 std::vector<double> radii, std::vector<int> segments)
    : num_actions_(num_actions),
      num_steps_(num_steps),
      radii_(std::move(radii)),
      segments_(std::move(segments)) {
  if (num_actions <= 0 || num_steps <= 0 || radii_.empty()) {
    std::ostringstream msg;
    msg << "HumanPrediction: need positive sizes, got num_actions=" << num_actions
        << " num_steps=" << num_steps << " num_spheres=" << radii_.size();
    throw std::invalid_argument(msg.str());
  }
  for (size_t i = 0; i < radii_.size(); ++i) {
    if (!(radii_[i] >= 0.0) || !std::isfinite(radii_[i])) {
      std::ostringstream msg;
      msg << "HumanPrediction: radius of sphere " << i << " is " << radii_[i]
          << ", must be finite and >= 0";
      throw std::invalid_argument(msg.str());
    }
  }
  if (segments_.empty()) {
    for (size_t i = 0; i < radii_.size(); ++i) segments_.push_back(static_cast<int>(i));
  } else if (segments_.size() != radii_.size()) {
    std::ostringstream msg;
    msg << "HumanPrediction: " << segments_.size() << " segment ids for "
        << radii_.size() << " spheres";
    throw std::invalid_argument(msg.str());
  }
  speed_allowances_.assign(radii_.size(), 0.0);
  probabilities_.assign(num_actions, 1.0 / num_actions);
  FactorizedGaussian unit;
  FactorizeGaussian(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), &unit);
  gaussians_.assign(static_cast<size_t>(num_actions) * num_steps * radii_.size(), unit);
  summaries_.resize(static_cast<size_t>(num_steps) * radii_.size());
  UpdateSummaries();
}

bool HumanPrediction::SetSphere(int action, int step, int sphere,
                                const Eigen::Vector3d& mean, const Eigen::Matrix3d& cov) {
  IPLAN_COLLISION_DEMAND(action >= 0 && action < num_actions_);
  IPLAN_COLLISION_DEMAND(step >= 0 && step < num_steps_);
  IPLAN_COLLISION_DEMAND(sphere >= 0 && sphere < num_spheres());
  FactorizedGaussian g;
  if (!FactorizeGaussian(mean, cov, &g)) return false;
  gaussians_[Index(action, step, sphere)] = g;
  summaries_up_to_date_ = false;
  return true;
}

bool HumanPrediction::set_speed_allowance(int sphere, double v) {
  IPLAN_COLLISION_DEMAND(sphere >= 0 && sphere < num_spheres());
  if (!(v >= 0.0) || !std::isfinite(v)) return false;
  speed_allowances_[static_cast<size_t>(sphere)] = v;
  return true;
}

void HumanPrediction::UpdateSummaries() {
  summaries_up_to_date_ = true;
  probability_sum_ = 0.0;
  for (double p : probabilities_) probability_sum_ += p;
  for (int t = 0; t < num_steps_; ++t) {
    for (int l = 0; l < num_spheres(); ++l) {
      Summary& s = summaries_[t * num_spheres() + l];
      // Centre of the axis-aligned box of the means; its half-diagonal-based
      // spread is the exact max distance from that centre to a mean.
      Eigen::Vector3d lo = sphere(0, t, l).mean;
      Eigen::Vector3d hi = lo;
      s.max_log_peak = -std::numeric_limits<double>::infinity();
      s.max_eigenvalue = 0.0;
      for (int c = 0; c < num_actions_; ++c) {
        const FactorizedGaussian& g = sphere(c, t, l);
        lo = lo.cwiseMin(g.mean);
        hi = hi.cwiseMax(g.mean);
        s.max_log_peak = std::max(s.max_log_peak, g.log_peak_density);
        s.max_eigenvalue = std::max(s.max_eigenvalue, g.eigenvalues[2]);
      }
      s.half_inverse_max_eigenvalue = 0.5 / s.max_eigenvalue;
      s.centre = 0.5 * (lo + hi);
      s.spread = 0.0;
      for (int c = 0; c < num_actions_; ++c) {
        s.spread = std::max(s.spread, (sphere(c, t, l).mean - s.centre).norm());
      }
    }
  }
}

std::string TrajectoryBoundParams::Validate() const {
  if (!(negligible >= 0.0 && negligible < 1.0)) {
    std::ostringstream msg;
    msg << "negligible = " << negligible << " must be in [0, 1)";
    return msg.str();
  }
  return {};
}

TrajectoryBoundWorkspace::TrajectoryBoundWorkspace(int max_robot_spheres,
                                                   int max_human_spheres)
    : log_upper(static_cast<size_t>(std::max(0, max_robot_spheres)) *
                static_cast<size_t>(std::max(0, max_human_spheres))),
      log_volume(log_upper.size()) {}

namespace {

// Mixture bound with log V(R) supplied by the caller (R = r_robot + r_human).
double MixtureBound(const HumanPrediction& prediction, int step, int sphere,
                    const Eigen::Vector3d& b, double R, double log_volume, int* argmax_action) {
  // Actions are solved 2 at a time (see internal::SolveSecularLanes).
  constexpr int L = 2;
  const int A = prediction.num_actions();
  double sum = 0.0;
  double best_term = -1.0;
  int best_action = -1;
  for (int start = 0; start < A; start += L) {
    const int m = std::min(L, A - start);
    double d[3][L], s[3][L], inv_s[3][L], dist[L], Rs[L], lambda[L];
    bool need[L];
    for (int l = 0; l < L; ++l) {
      const FactorizedGaussian& g = prediction.sphere(start + (l < m ? l : 0), step, sphere);
      const Eigen::Vector3d dv = g.eigenvectors.transpose() * (g.mean - b);
      for (int i = 0; i < 3; ++i) {
        d[i][l] = dv[i];
        s[i][l] = g.eigenvalues[i];
        inv_s[i][l] = g.inverse_eigenvalues[i];
      }
      Rs[l] = R;
      const double dist2 = dv.squaredNorm();
      dist[l] = std::sqrt(dist2);
      need[l] = dist2 > R * R;
    }
    internal::SolveSecularLanes<L>(d, s, inv_s, dist, Rs, need, lambda, nullptr);
    for (int l = 0; l < m; ++l) {
      const int c = start + l;
      const double p = prediction.action_probability(c);
      if (p <= 0.0) continue;
      const double log_peak = prediction.sphere(c, step, sphere).log_peak_density;
      const double dd[3] = {d[0][l], d[1][l], d[2][l]};
      const double ss[3] = {s[0][l], s[1][l], s[2][l]};
      const double lb = need[l] ? internal::LogBoundAt(dd, ss, lambda[l], log_volume, log_peak)
                                : log_volume + log_peak;
      const double term = p * (lb >= 0.0 ? 1.0 : std::exp(lb));
      sum += term;
      if (term > best_term) {
        best_term = term;
        best_action = c;
      }
    }
  }
  if (argmax_action != nullptr) *argmax_action = best_action;
  return std::min(sum, 1.0);
}

}  // namespace

double EvaluateMixtureBound(const HumanPrediction& prediction, int step, int sphere,
                            const Eigen::Vector3d& b, double r_robot, int* argmax_action) {
  const double R = r_robot + prediction.radius(sphere);
  return MixtureBound(prediction, step, sphere, b, R, std::log(BallVolume(R)), argmax_action);
}

// Pruning, and why it is safe.
//
// For one action c, a pair's bound is min(1, V(R) max_{x in B(b,R)} f_c(x)).
// Every x in the ball satisfies ||x - mu_c|| >= delta_c := max(0, ||mu_c - b||
// - R) (triangle inequality), and (x - mu)^T Sigma^-1 (x - mu) >= ||x - mu||^2
// / s_max (Rayleigh quotient). Hence
//   U_c := min(1, V(R) exp(log_peak_c - delta_c^2 / (2 s_max,c)))
// is an upper bound on the pair bound of action c, and
//   U2 := sum_c p(c) U_c                                      (level 2)
// bounds the pair's mixture. With m, rho the centre and radius of a ball that
// holds every mu_c of this (step, sphere) (HumanPrediction::Summary),
// ||mu_c - b|| >= ||m - b|| - rho, so delta_c >= delta := max(0, ||m - b|| -
// rho - R); with L = max_c log_peak_c and S = max_c s_max,c,
//   U1 := P_sum * min(1, V(R) exp(L - delta^2 / (2 S))) >= U2  (level 1)
// (P_sum = sum_c p(c)). A pair with an upper bound U <= the best mixture found
// so far at this waypoint cannot raise the maximum (nor change the argmax,
// ties keep the first), so skipping it leaves the result exact. A pair with
// U <= `negligible` is skipped too; its U is remembered, and if the waypoint's
// exact maximum stays below `negligible` the reported bound is the largest
// such U, which is >= the true maximum: the result is always an upper bound.
namespace {

// The search for one waypoint's maximum over its sphere pairs (see above).
struct PairSearch {
  const HumanPrediction& prediction;
  const RobotSpheresTrajectory& trajectory;
  const TrajectoryBoundParams& params;
  const double* log_upper;
  const double* log_volume;
  double log_negligible;
  int w, t, S, H, A;
  WaypointBound* res;
  double best = -1.0;  // best exact mixture so far (-1: none yet)
  double log_best = -std::numeric_limits<double>::infinity();
  double skipped_max = 0.0;  // largest U of pairs skipped as negligible
  double log_skipped_max = -std::numeric_limits<double>::infinity();  // same, level 1 (log)

  // Level 2, then the exact mixture, of one pair unless pruned.
  void Evaluate(int pair) {
    const int k = pair / H;
    const int l = pair % H;
    const double lu = log_upper[pair];
    if (lu <= log_negligible) {
      log_skipped_max = std::max(log_skipped_max, lu);
      ++res->pairs_pruned;
      return;
    }
    if (lu <= log_best) {
      ++res->pairs_pruned;
      return;
    }
    const Eigen::Vector3d b = trajectory.centres.col(static_cast<Eigen::Index>(w) * S + k);
    const double r1 = trajectory.radii[k];
    const double R = r1 + prediction.radius(l);
    const double log_v = log_volume[pair];
    double u2 = 0.0;
    for (int c = 0; c < A; ++c) {
      const double p = prediction.action_probability(c);
      if (p <= 0.0) continue;
      const FactorizedGaussian& g = prediction.sphere(c, t, l);
      const double delta = std::max(0.0, (g.mean - b).norm() - R);
      const double lu_c = log_v + g.log_peak_density - delta * delta * (0.5 * g.inverse_eigenvalues[2]);
      u2 += p * (lu_c >= 0.0 ? 1.0 : std::exp(lu_c));
    }
    if (u2 <= params.negligible) {
      skipped_max = std::max(skipped_max, u2);
      ++res->pairs_pruned;
      return;
    }
    if (u2 <= best) {
      ++res->pairs_pruned;
      return;
    }
    int action = -1;
    const double value = MixtureBound(prediction, t, l, b, R, log_v, &action);
    ++res->pairs_evaluated;
    if (value > best) {
      best = value;
      log_best = std::log(value);
      res->robot_sphere = k;
      res->human_sphere = l;
      res->action = action;
    }
  }

  // The waypoint's bound from the search: exact when some pair reached
  // `negligible`, else the largest skipped upper bound.
  void Finish() {
    skipped_max = std::max(skipped_max, std::exp(log_skipped_max));
    if (res->robot_sphere >= 0) {
      res->robot_link = trajectory.links[res->robot_sphere];
      res->human_segment = prediction.segment(res->human_sphere);
    }
    if (best >= params.negligible && best >= 0.0) {
      res->bound = best;
      res->exact = true;
    } else {
      res->bound = std::max(std::max(best, 0.0), std::min(skipped_max, 1.0));
      res->exact = skipped_max <= std::max(best, 0.0);
    }
  }
};

// Level 1 for every pair of waypoint w, in the log domain (no exp), into
// log_upper; returns the pair with the largest (-1 when there is none).
int LevelOneBounds(const HumanPrediction& prediction, const RobotSpheresTrajectory& trajectory, int w, int t,
                   double log_psum, const double* log_volume, double* log_upper) {
  const int S = trajectory.num_spheres();
  const int H = prediction.num_spheres();
  int first = -1;
  double first_value = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < S; ++k) {
    const Eigen::Vector3d b = trajectory.centres.col(static_cast<Eigen::Index>(w) * S + k);
    const double r1 = trajectory.radii[k];
    for (int l = 0; l < H; ++l) {
      const HumanPrediction::Summary& sm = prediction.summary(t, l);
      const double R = r1 + prediction.radius(l);
      const double delta = std::max(0.0, (sm.centre - b).norm() - sm.spread - R);
      const double lu = log_psum + std::min(0.0, log_volume[k * H + l] + sm.max_log_peak -
                                                     delta * delta * sm.half_inverse_max_eigenvalue);
      log_upper[k * H + l] = lu;
      if (lu > first_value) {
        first_value = lu;
        first = k * H + l;
      }
    }
  }
  return first;
}

}  // namespace

void EvaluateTrajectoryBound(const HumanPrediction& prediction,
                             const RobotSpheresTrajectory& trajectory,
                             const TrajectoryBoundParams& params,
                             TrajectoryBoundWorkspace* workspace,
                             std::vector<WaypointBound>* out) {
  IPLAN_COLLISION_DEMAND(workspace != nullptr && out != nullptr);
  IPLAN_COLLISION_DEMAND(prediction.summaries_up_to_date());
  const int S = trajectory.num_spheres();
  const int H = prediction.num_spheres();
  const int W = trajectory.num_waypoints();
  const int A = prediction.num_actions();
  IPLAN_COLLISION_DEMAND(static_cast<int>(trajectory.links.size()) == S);
  IPLAN_COLLISION_DEMAND(trajectory.centres.cols() == static_cast<Eigen::Index>(W) * S);
  IPLAN_COLLISION_DEMAND(workspace->log_upper.size() >= static_cast<size_t>(S) * H);
  IPLAN_COLLISION_DEMAND(workspace->log_volume.size() >= static_cast<size_t>(S) * H);
  if (static_cast<int>(out->size()) != W) out->resize(W);

  const double log_negligible =
      params.negligible > 0.0 ? std::log(params.negligible)
                              : -std::numeric_limits<double>::infinity();
  const double log_psum = std::log(prediction.probability_sum());
  double* log_upper = workspace->log_upper.data();
  double* log_volume = workspace->log_volume.data();
  for (int k = 0; k < S; ++k) {
    for (int l = 0; l < H; ++l) {
      log_volume[k * H + l] = std::log(BallVolume(trajectory.radii[k] + prediction.radius(l)));
    }
  }

  for (int w = 0; w < W; ++w) {
    const int t = trajectory.steps[w];
    IPLAN_COLLISION_DEMAND(t >= 0 && t < prediction.num_steps());
    WaypointBound& res = (*out)[w];
    res = WaypointBound{};
    const int first = LevelOneBounds(prediction, trajectory, w, t, log_psum, log_volume, log_upper);
    PairSearch search{prediction, trajectory, params, log_upper, log_volume, log_negligible, w, t, S, H, A, &res};
    if (first >= 0) search.Evaluate(first);
    for (int pair = 0; pair < S * H; ++pair) {
      if (pair != first) search.Evaluate(pair);
    }
    search.Finish();
  }
}

}  // namespace iplan::collision

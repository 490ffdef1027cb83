// The dynamic cost term (METHOD.md sections 4 and 5): dynamic =
// w sum_i max(0, P_i - tau)^2, P_i the collision bound of free waypoint i
// against the predicted people, tau = dynamic_activation (1 - delta_CL).
#include <algorithm>
#include <cmath>
#include <limits>

#include "iplan/cell/people.h"
#include "planner_model.h"

namespace iplan::planning::internal {

// Bounds of the free waypoints only (ev->bounds[i - k]). Pairs whose upper
// bound is below tau are not evaluated exactly: a waypoint whose bound is
// <= tau costs nothing and has no gradient, and one above tau gets the same
// exact value and argmax pair as with the default (see
// EvaluateTrajectoryBound's pruning); reported values below tau are upper
// bounds, which also keeps the safety test (>= 1 - delta_CL > tau)
// unchanged. Exact values for the result: ExactBounds.
//
// Several people: P_i = min(1, sum_p P_i^p) (cell::UnionBound), each person's
// pairs pruned at tau / N, so that a waypoint whose persons are all culled
// has P_i <= tau (no cost, no gradient, still safe); the gradient is the
// sum of each person's argmax-pair gradient, weighted by its share.
void PlannerModel::AddDynamicCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const {
  const double tau = params.dynamic_activation * Threshold();
  const int N = static_cast<int>(at.people.size());
  collision::TrajectoryBoundParams bp;
  bp.negligible = tau * (1.0 - 1e-9) / N;
  if (N == 1) {
    FindActiveWaypoints(at, 0, std::log(bp.negligible), ws);
    EvaluateActiveBounds(at, 0, bp, ws, &ev->bounds);
  } else {
    ws->person_bounds.resize(static_cast<std::size_t>(N));
    for (int p = 0; p < N; ++p) {
      FindActiveWaypoints(at, p, std::log(bp.negligible), ws);
      EvaluateActiveBounds(at, p, bp, ws, &ws->person_bounds[static_cast<std::size_t>(p)]);
    }
    CombineBounds(at, ws, &ev->bounds);
  }
  const double w = params.weights.dynamic;
  for (int i = at.k; i < at.n; ++i) {
    const double P = ev->bounds[i - at.k].bound;
    if (P <= tau) continue;
    ev->dynamic += w * (P - tau) * (P - tau);
    if (!G) continue;
    for (int p = 0; p < N; ++p) {
      const collision::WaypointBound& wb = N == 1 ? ev->bounds[i - at.k] : ws->person_bounds[p][i - at.k];
      if (wb.robot_sphere < 0) continue;
      AddBoundGradient(at, p, i, wb, w * 2.0 * (P - tau) * wb.bound, ws, G);
    }
  }
}

void PlannerModel::CombineBounds(const Problem& at, Workspace* ws, std::vector<collision::WaypointBound>* out) const {
  const std::size_t N = at.people.size();
  out->assign(static_cast<std::size_t>(at.n - at.k), collision::WaypointBound{});
  ws->shares.resize(N);
  for (std::size_t w = 0; w < out->size(); ++w) {
    collision::WaypointBound& b = (*out)[w];
    double top = -1.0;
    bool exact = true;
    for (std::size_t p = 0; p < N; ++p) {
      const collision::WaypointBound& s = ws->person_bounds[p][w];
      ws->shares[p] = s.bound;
      exact = exact && s.exact;
      if (s.bound > top) {
        top = s.bound;
        b = s;
      }
    }
    b.bound = cell::UnionBound(ws->shares);
    b.exact = exact;
  }
}

// Waypoints where every pair's level-1 upper bound (the library's first
// pruning test) is <= negligible contribute nothing; they are recognised
// per link group (a ball around the link's spheres; every sphere's level-1
// bound is at most the group's) and not passed on.
void PlannerModel::FindActiveWaypoints(const Problem& at, int p, double log_negligible, Workspace* ws) const {
  const Problem::Person& person = at.people[static_cast<std::size_t>(p)];
  const collision::HumanPrediction& hp = *person.prediction;
  const std::vector<double>& group_log_volume = ws->group_log_volume[static_cast<std::size_t>(p)];
  const int H = hp.num_spheres();
  const double log_psum = std::log(hp.probability_sum());
  ws->active.clear();
  ws->group_needed.assign(link_groups.size(), 0);
  ws->culled_log_bound.assign(static_cast<std::size_t>(at.n - at.k), -std::numeric_limits<double>::infinity());
  for (int i = at.k; i < at.n; ++i) {
    const int t = person.steps[i];
    const collision::RobotData& d = ws->data[i];
    bool may_matter = false;
    double& culled = ws->culled_log_bound[static_cast<std::size_t>(i - at.k)];
    for (std::size_t g = 0; g < link_groups.size(); ++g) {
      Eigen::Vector3d c;
      const double cover = LinkBall(d, link_groups[g], &c);
      for (int l = 0; l < H; ++l) {
        const collision::HumanPrediction::Summary& sm = hp.summary(t, l);
        const double delta = std::max(0.0, (sm.centre - c).norm() - sm.spread - cover - hp.radius(l));
        const double lu = log_psum + std::min(0.0, group_log_volume[g * H + l] + sm.max_log_peak -
                                                       delta * delta * sm.half_inverse_max_eigenvalue);
        culled = std::max(culled, lu);
        if (lu > log_negligible) {
          may_matter = true;
          ws->group_needed[g] = 1;
          break;
        }
      }
    }
    if (may_matter) ws->active.push_back(i);
  }
}

// Only the spheres of links that may matter at some active waypoint, in
// their original order: the others' pairs would all be skipped as
// negligible, so the maximum and its argmax pair are unchanged.
void PlannerModel::EvaluateActiveBounds(const Problem& at, int p, const collision::TrajectoryBoundParams& bp,
                                        Workspace* ws, std::vector<collision::WaypointBound>* out) const {
  const Problem::Person& person = at.people[static_cast<std::size_t>(p)];
  const int num_active = static_cast<int>(ws->active.size());
  out->assign(at.n - at.k, collision::WaypointBound{});
  // An upper bound of the culled waypoints: the pruning threshold, or with
  // several people their level-1 bound (much smaller for a person far away,
  // who then adds next to nothing to the union).
  const bool several = at.people.size() > 1;
  for (std::size_t w = 0; w < out->size(); ++w) {
    collision::WaypointBound& b = (*out)[w];
    b.bound = several ? std::exp(ws->culled_log_bound[w]) : bp.negligible;
    b.exact = false;
  }
  if (num_active == 0) return;
  collision::RobotSpheresTrajectory& sub = ws->sub;
  ws->sub_spheres.clear();
  sub.radii.clear();
  sub.links.clear();
  for (int sp = 0; sp < static_cast<int>(radii.size()); ++sp) {
    if (!ws->group_needed[sphere_group[sp]]) continue;
    ws->sub_spheres.push_back(sp);
    sub.radii.push_back(radii[sp]);
    sub.links.push_back(links[sp]);
  }
  const int SS = static_cast<int>(ws->sub_spheres.size());
  sub.centres.resize(3, static_cast<Eigen::Index>(num_active) * SS);
  sub.steps.clear();
  for (int a = 0; a < num_active; ++a) {
    const int i = ws->active[a];
    for (int j = 0; j < SS; ++j)
      sub.centres.col(static_cast<Eigen::Index>(a) * SS + j) = ws->data[i].p_WS.col(ws->sub_spheres[j]);
    sub.steps.push_back(person.steps[i]);
  }
  collision::EvaluateTrajectoryBound(*person.prediction, sub, bp, ws->bound_ws.get(), &ws->active_bounds);
  for (int a = 0; a < num_active; ++a) {
    collision::WaypointBound b = ws->active_bounds[a];
    if (b.robot_sphere >= 0) b.robot_sphere = ws->sub_spheres[b.robot_sphere];
    (*out)[ws->active[a] - at.k] = b;
  }
}

// Gradient of the argmax pair's mixture bound w.r.t. the robot sphere
// centre b: by the envelope theorem, d log f(x_max)/db equals the density's
// log-gradient at x_max, -Sigma^-1 (x_max - mu). The mixture's log-gradient
// weights each action by its share; when the mean lies inside the ball
// (gradient 0) the direction towards the mean, scaled by 1/s_min, is used
// instead. `scale` (2 w (P - tau) P) multiplies it by the clamped bound, so
// it stays bounded when the raw bound exceeds 1.
void PlannerModel::AddBoundGradient(const Problem& at, int p, int i, const collision::WaypointBound& wb, double scale,
                                    Workspace* ws, Eigen::MatrixXd* G) const {
  const Problem::Person& person = at.people[static_cast<std::size_t>(p)];
  const collision::HumanPrediction& hp = *person.prediction;
  const int s = wb.robot_sphere, l = wb.human_sphere, step = person.steps[i];
  const Eigen::Vector3d b = ws->data[i].p_WS.col(s);
  const double R = radii[s] + hp.radius(l);
  Eigen::Vector3d glog = Eigen::Vector3d::Zero();
  double total = 0.0;
  for (int c = 0; c < hp.num_actions(); ++c) {
    const double pc = hp.action_probability(c);
    if (pc <= 0.0) continue;
    const collision::FactorizedGaussian& g = hp.sphere(c, step, l);
    const collision::PairBound pb = collision::EvaluatePairBound(g, b, R);
    const double u = pc * std::exp(std::min(pb.log_bound, 50.0));
    Eigen::Vector3d dir;
    if (pb.lambda > 0.0) {
      dir = -(g.inverse * (pb.x_max - g.mean));
    } else {
      dir = (g.mean - b) * g.inverse_eigenvalues.maxCoeff();
    }
    glog += u * dir;
    total += u;
  }
  if (total <= 0.0) return;
  glog /= total;
  const Eigen::Vector3d gp = scale * glog;
  chains->AddPointGradient(ws->data[i], links[s], b, gp, G->col(i));
}

}  // namespace iplan::planning::internal

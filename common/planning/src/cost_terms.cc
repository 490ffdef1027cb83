// The cost terms of METHOD.md section 5 (planner.h gives each formula),
// except the dynamic term (dynamic_cost.cc). Each adds its value to the
// CostTerms and, with G != nullptr, its gradient to the free columns of G.
#include <algorithm>
#include <cmath>

#include "iplan/cell/joint_trajectory.h"
#include "planner_model.h"

namespace iplan::planning::internal {

void PlannerModel::Evaluate(const Problem& at, const Eigen::MatrixXd& Q, Workspace* ws, CostTerms* ev,
                            Eigen::MatrixXd* G) const {
  ev->smooth = ev->obstacle = ev->dynamic = ev->goal = ev->limits = ev->separation = ev->ssm = 0.0;
  if (G) G->setZero(at.nq, at.n + 1);
  // Accelerations a_i, i = 0..n, and velocities v_i, i = 0..n-1.
  cell::FiniteDifferenceAccelerations(Q, at.qdot0, at.dt, &ws->A);
  cell::FiniteDifferenceVelocities(Q, at.dt, &ws->V);
  AddSmoothnessCost(at, ws, ev, G);
  AddGoalCost(at, Q, ev, G);
  AddLimitCost(at, ws, ev, G);
  // Forward kinematics of the free waypoints (the only ones the costs use).
  for (int i = at.k; i < at.n; ++i) collision::CalcForwardKinematics(robot, Q.col(i), &ws->data[i]);
  // The separation monitor's rule also needs the plan's speed at the last free waypoint.
  const bool ssm = SsmLastWaypoint(at) >= at.k;
  if (ssm) collision::CalcForwardKinematics(robot, Q.col(at.n), &ws->data[at.n]);
  AddObstacleCost(at, ws, ev, G);
  if (!at.people.empty()) AddDynamicCost(at, ws, ev, G);
  if (!at.people.empty() && params.human_separation > 0.0) AddSeparationCost(at, ws, ev, G);
  if (ssm) AddSsmCost(at, ws, ev, G);
  ev->total = ev->smooth + ev->obstacle + ev->dynamic + ev->goal + ev->limits + ev->separation + ev->ssm;
}

// smoothness = w sum_i dt ||a_i||^2.
void PlannerModel::AddSmoothnessCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const {
  const double w = params.weights.smoothness, dt = at.dt;
  const Eigen::MatrixXd& A = ws->A;
  ev->smooth = w * dt * A.squaredNorm();
  if (!G) return;
  for (int j = at.k; j < at.n; ++j) G->col(j) += w * (2.0 / dt) * (A.col(j - 1) - 2.0 * A.col(j) + A.col(j + 1));
}

// goal = w sum_i dt ||q_i - q_goal||^2 over the free waypoints and the goal.
void PlannerModel::AddGoalCost(const Problem& at, const Eigen::MatrixXd& Q, CostTerms* ev, Eigen::MatrixXd* G) const {
  const double w = params.weights.goal, dt = at.dt;
  for (int i = at.k; i <= at.n; ++i) ev->goal += w * dt * (Q.col(i) - at.q_goal).squaredNorm();
  if (!G) return;
  for (int j = at.k; j < at.n; ++j) G->col(j) += 2.0 * w * dt * (Q.col(j) - at.q_goal);
}

// limits = w sum of the squared, normalised excess of |v| and |a| over
// limit_scale x their limits (terms touching free waypoints).
void PlannerModel::AddLimitCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const {
  const double w = params.weights.limits, scale = params.limit_scale, dt = at.dt;
  const int n = at.n, k = at.k;
  const Eigen::MatrixXd& V = ws->V;
  const Eigen::MatrixXd& A = ws->A;
  for (int i = std::max(0, k - 1); i < n; ++i) {
    for (int j = 0; j < at.nq; ++j) {
      const double e = (std::abs(V(j, i)) - scale * vmax[j]) / vmax[j];
      if (e <= 0.0) continue;
      ev->limits += w * e * e;
      if (!G) continue;
      const double d = w * 2.0 * e * (V(j, i) < 0 ? -1.0 : 1.0) / vmax[j] / dt;
      if (i + 1 >= k && i + 1 < n) (*G)(j, i + 1) += d;
      if (i >= k && i < n) (*G)(j, i) -= d;
    }
  }
  for (int i = std::max(0, k - 1); i <= n; ++i) {
    for (int j = 0; j < at.nq; ++j) {
      const double e = (std::abs(A(j, i)) - scale * amax[j]) / amax[j];
      if (e <= 0.0) continue;
      ev->limits += w * e * e;
      if (!G) continue;
      const double d = w * 2.0 * e * (A(j, i) < 0 ? -1.0 : 1.0) / amax[j] / (dt * dt);
      if (i - 1 >= k && i - 1 < n) (*G)(j, i - 1) += d;
      if (i >= k && i < n) (*G)(j, i) -= 2.0 * d;
      if (i + 1 >= k && i + 1 < n) (*G)(j, i + 1) += d;
    }
  }
}

// obstacle = w sum_i sum_(sphere, object) max(0, margin - d)^2. Per link, a
// ball around its spheres first: the signed distance is 1-Lipschitz, so when
// the ball's centre is farther than its cover radius + margin (+ 1e-9
// against rounding) from an object, none of the link's spheres is within the
// margin of it.
void PlannerModel::AddObstacleCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const {
  const double w = params.weights.obstacle, margin = params.obstacle_margin;
  const int S = static_cast<int>(radii.size());
  const int NO = NumObjects(at);
  const int NG = static_cast<int>(link_groups.size());
  ws->far.resize(static_cast<std::size_t>(NG) * NO);
  for (int i = at.k; i < at.n; ++i) {
    const collision::RobotData& d = ws->data[i];
    for (int g = 0; g < NG; ++g) {
      Eigen::Vector3d c;
      const double cover = LinkBall(d, link_groups[g], &c);
      for (int o = 0; o < NO; ++o) {
        const auto& ob = Object(at, o);
        double lower_bound = (c - ob.centre_W).norm() - ob.bounding_radius - cover;
        if (lower_bound < margin + 1e-9) lower_bound = PointSignedDistance(ob, c, nullptr) - cover;
        ws->far[g * NO + o] = lower_bound >= margin + 1e-9;
      }
    }
    for (int s = 0; s < S; ++s) {
      const Eigen::Vector3d p = d.p_WS.col(s);
      Eigen::Vector3d gp = Eigen::Vector3d::Zero();
      bool any = false;
      for (int o = 0; o < NO; ++o) {
        if (!Checked(s, o) || ws->far[sphere_group[s] * NO + o]) continue;
        const auto& ob = Object(at, o);
        if ((p - ob.centre_W).norm() - ob.bounding_radius - radii[s] >= margin) continue;
        // The normal only for spheres within the margin (the same distance).
        const double dist = PointSignedDistance(ob, p, nullptr) - radii[s];
        if (dist >= margin) continue;
        ev->obstacle += w * (margin - dist) * (margin - dist);
        if (!G) continue;
        Eigen::Vector3d n_W;
        PointSignedDistance(ob, p, &n_W);
        gp -= 2.0 * w * (margin - dist) * n_W;
        any = true;
      }
      if (G && any) chains->AddPointGradient(d, links[s], p, gp, G->col(i));
    }
  }
}

// separation = w sum p(c) max(0, D - dist)^2: the keep-out from the means of
// the likely actions (PlannerParams::human_separation = D), summed over the
// people.
void PlannerModel::AddSeparationCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const {
  for (const Problem::Person& person : at.people) AddPersonSeparationCost(person, at, ws, ev, G);
}

void PlannerModel::AddPersonSeparationCost(const Problem::Person& person, const Problem& at, Workspace* ws,
                                           CostTerms* ev, Eigen::MatrixXd* G) const {
  const collision::HumanPrediction& hp = *person.prediction;
  const int H = hp.num_spheres();
  const double D = params.human_separation, w = params.weights.separation;
  for (int i = at.k; i < at.n; ++i) {
    const collision::RobotData& d = ws->data[i];
    const int t = person.steps[i];
    for (std::size_t g = 0; g < link_groups.size(); ++g) {
      // A ball around the link's spheres first, as for the obstacles.
      Eigen::Vector3d c;
      const double cover = LinkBall(d, link_groups[g], &c);
      for (int l = 0; l < H; ++l) {
        // The bounding ball of the actions' means bounds every mean.
        const collision::HumanPrediction::Summary& sm = hp.summary(t, l);
        if ((c - sm.centre).norm() - sm.spread - cover - hp.radius(l) >= D) continue;
        for (int a = 0; a < hp.num_actions(); ++a) {
          const double pa = hp.action_probability(a);
          if (pa < kSeparationMinProbability) continue;
          const Eigen::Vector3d& mu = hp.sphere(a, t, l).mean;
          for (int s : link_groups[g]) {
            const Eigen::Vector3d p = d.p_WS.col(s);
            const Eigen::Vector3d diff = p - mu;
            const double len = diff.norm();
            const double dist = len - radii[s] - hp.radius(l);
            if (dist >= D) continue;
            ev->separation += w * pa * (D - dist) * (D - dist);
            if (!G || len < 1e-9) continue;
            const Eigen::Vector3d gp = -2.0 * w * pa * (D - dist) * diff / len;
            chains->AddPointGradient(d, links[s], p, gp, G->col(i));
          }
        }
      }
    }
  }
}

}  // namespace iplan::planning::internal

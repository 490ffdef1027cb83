// The ITOMP optimiser of METHOD.md section 5: from an initial trajectory
// (the problem's base, perturbed for every optimiser but the first),
// covariant gradient descent (the gradient preconditioned by the inverse
// smoothness metric) with backtracking line search and projection onto the
// joint limits, then the feasibility check of the result.
#include <algorithm>
#include <cmath>
#include <random>

#include "planner_model.h"

namespace iplan::planning::internal {

void PlannerModel::Project(const Problem& at, Eigen::MatrixXd* Q) const {
  const double mg = params.position_margin;
  for (int i = at.k; i < at.n; ++i)
    Q->col(i) = Q->col(i).array().max(lower.array() + mg).min(upper.array() - mg).matrix();
}

void PlannerModel::Check(const Problem& at, const CostTerms& ev, Workspace* ws, Candidate* c) const {
  const Eigen::MatrixXd& Q = c->Q;
  c->static_ok = CheckLimits(robot, Q, at.dt, at.qdot0).empty();
  const int sub = params.collision_check_substeps;
  collision::RobotData& d = ws->data[0];
  const int first = std::max(0, at.k - 1);
  // A start that is already too close (a box put down against the arm, or
  // reached by the frozen prefix before the box was seen) cannot be
  // undone: from there a feasible trajectory may leave but not go deeper.
  collision::CalcForwardKinematics(robot, Q.col(first), &d);
  const double floor = std::min(params.min_clearance, Clearance(d, &at.obstacles));
  double clear = std::numeric_limits<double>::infinity();
  Eigen::VectorXd q(at.nq);
  for (int i = first; i <= at.n && clear >= floor; ++i) {
    const int count = i < at.n ? sub : 1;
    for (int s = 0; s < count; ++s) {
      q = Q.col(i) + (static_cast<double>(s) / sub) *
                         (i < at.n ? Eigen::VectorXd(Q.col(i + 1) - Q.col(i)) : Eigen::VectorXd::Zero(at.nq));
      collision::CalcForwardKinematics(robot, q, &d);
      clear = std::min(clear, Clearance(d, &at.obstacles));
    }
  }
  c->min_clearance = clear;
  c->static_ok = c->static_ok && clear >= floor;
  c->bounds.clear();
  c->max_bound = 0.0;
  c->first_unsafe = -1;
  if (!at.people.empty()) {
    c->bounds = at.fixed_bounds;
    for (int i = at.k; i < at.n; ++i) c->bounds[i] = ev.bounds[i - at.k].bound;
    for (int i = at.k; i <= at.n; ++i) {
      c->max_bound = std::max(c->max_bound, c->bounds[i]);
      if (c->first_unsafe < 0 && c->bounds[i] >= Threshold()) c->first_unsafe = i;
    }
  }
  c->ssm = JudgeSsm(at, Q, at.ssm_from, at.n, ws);
  c->safe = c->first_unsafe < 0 && c->ssm.ok();
}

// Initial trajectory from the base (perturbed for o > 0: a smooth bump of
// seeded size towards a seeded via point) and its cost.
void PlannerModel::StartOptimizer(const Problem& at, int o, std::uint64_t seed, Workspace* ws,
                                  OptimizerState* st) const {
  std::mt19937_64 rng(SplitMix(seed ^ SplitMix(static_cast<std::uint64_t>(o) + 1)));
  Eigen::MatrixXd& Q = st->Q;
  Q = at.base;
  if (o > 0 && at.perturb_base) {
    std::normal_distribution<double> nd(0.0, params.initial_perturbation);
    Eigen::VectorXd delta(at.nq);
    for (int j = 0; j < at.nq; ++j) delta[j] = nd(rng);
    std::uniform_real_distribution<double> ud(0.25, 0.75);
    const double centre = ud(rng);  // via-point position along the free part
    for (int i = at.k; i < at.n; ++i) {
      const double s = static_cast<double>(i - at.k + 1) / (at.n - at.k + 1);
      const double prof = s <= centre ? std::sin(0.5 * M_PI * s / centre)
                                      : std::sin(0.5 * M_PI * (1.0 - s) / (1.0 - centre));
      Q.col(i) += prof * prof * delta;
    }
    Project(at, &Q);
  }
  Evaluate(at, Q, ws, &st->ev, &st->G);
  st->started = true;
}

// Covariant gradient descent with backtracking until `until` accepted
// iterations (or convergence / no decrease / max_iterations).
void PlannerModel::IterateOptimizer(const Problem& at, int until, Workspace* ws, OptimizerState* st) const {
  const double inv_ws = 1.0 / params.weights.smoothness;
  until = std::min(until, params.max_iterations);
  while (!st->done && st->iterations < until && !at.OutOfTime()) {
    const Eigen::MatrixXd D = st->G.middleCols(at.k, at.m) * at.Hinv * inv_ws;
    double alpha = params.step_size;
    bool accepted = false;
    for (int ls = 0; ls < 6 && !at.OutOfTime(); ++ls) {
      st->Qn = st->Q;
      st->Qn.middleCols(at.k, at.m) -= alpha * D;
      Project(at, &st->Qn);
      Evaluate(at, st->Qn, ws, &st->ev_new, &st->G_new);
      if (st->ev_new.total < st->ev.total) {
        accepted = true;
        break;
      }
      alpha *= 0.5;
    }
    if (!accepted) {
      st->done = true;
      break;
    }
    const double rel = (st->ev.total - st->ev_new.total) / std::max(st->ev.total, 1e-12);
    st->Q.swap(st->Qn);
    st->G.swap(st->G_new);
    std::swap(st->ev, st->ev_new);
    st->checked = false;
    ++st->iterations;
    if (rel < params.convergence_tolerance) st->done = true;
  }
  if (st->iterations >= params.max_iterations) st->done = true;
}

// Feasibility of the current Q (once per Q).
void PlannerModel::CheckOptimizer(const Problem& at, Workspace* ws, OptimizerState* st, Clock::time_point t0) const {
  if (st->checked) return;
  Candidate& c = st->c;
  c.Q = st->Q;
  c.cost = st->ev.total;
  Check(at, st->ev, ws, &c);
  if (c.static_ok && c.safe && c.first_feasible_time < 0.0) c.first_feasible_time = Seconds(t0, Clock::now());
  st->checked = true;
}

}  // namespace iplan::planning::internal

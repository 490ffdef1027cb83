#include "iplan/planning/planner.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <Eigen/Cholesky>

#include "clearance.h"

namespace iplan::planning {

using collision::HumanPrediction;

// Actions predicted with less probability than this do not shape the
// keep-out (PlannerParams::human_separation); each other action's mean
// weighs in with its probability.
constexpr double kSeparationMinProbability = 0.3;
// Peak over mean joint speed of the rest-to-rest motions the optimiser finds
// within the velocity limits: a motion whose largest joint distance over its
// velocity limit is t_min gets at least this times t_min.
constexpr double kRestToRestPeakFactor = 1.5;
using collision::RobotData;
using collision::RobotModel;
using Clock = std::chrono::steady_clock;

Goal Goal::Joint(Eigen::VectorXd q) {
  Goal g;
  g.kind = Kind::kJoint;
  g.q = std::move(q);
  return g;
}

Goal Goal::Pose(const Eigen::Vector3d& p_WE, const Eigen::Quaterniond& R_WE) {
  Goal g;
  g.kind = Kind::kPose;
  g.p_WE = p_WE;
  g.R_WE = R_WE;
  return g;
}

const char* ToString(PlanStatus status) {
  switch (status) {
    case PlanStatus::kSuccess: return "success";
    case PlanStatus::kSuccessAfterWait: return "success_after_wait";
    case PlanStatus::kNoSafeTrajectory: return "no_safe_trajectory";
    case PlanStatus::kInfeasible: return "infeasible";
    case PlanStatus::kIkFailed: return "ik_failed";
    case PlanStatus::kGoalInCollision: return "goal_in_collision";
  }
  return "unknown";
}

namespace {

std::string Vec(const Eigen::VectorXd& v) {
  std::ostringstream s;
  s.precision(10);
  s << "[";
  for (int i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v[i];
  s << "]";
  return s.str();
}

std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

std::string CheckLimits(const RobotModel& robot, const Eigen::MatrixXd& Q, double dt,
                        const Eigen::VectorXd& qdot0, double tol) {
  const int nq = robot.nq;
  if (Q.rows() != nq) return "trajectory has " + std::to_string(Q.rows()) + " rows, robot nq " +
                             std::to_string(nq);
  const int W = static_cast<int>(Q.cols());
  std::ostringstream s;
  s.precision(10);
  for (int j = 0; j < nq; ++j) {
    const collision::JointLimits& L = robot.joints[robot.q_joints[j]].limits;
    const double v0 = qdot0.size() == nq ? qdot0[j] : 0.0;
    for (int i = 0; i < W; ++i) {
      const double q = Q(j, i);
      if (!std::isfinite(q) || q < L.lower - tol || q > L.upper + tol) {
        s << "position of joint " << j << " at waypoint " << i << " is " << q << ", limits ["
          << L.lower << ", " << L.upper << "]";
        return s.str();
      }
      if (i + 1 < W) {
        const double v = (Q(j, i + 1) - q) / dt;
        if (std::abs(v) > L.velocity * (1.0 + tol)) {
          s << "velocity of joint " << j << " at waypoint " << i << " is " << v << ", limit "
            << L.velocity;
          return s.str();
        }
      }
      const double prev = i == 0 ? Q(j, 0) - v0 * dt : Q(j, i - 1);
      const double next = i + 1 < W ? Q(j, i + 1) : Q(j, i);
      const double a = (next - 2.0 * q + prev) / (dt * dt);
      if (std::abs(a) > L.acceleration * (1.0 + tol)) {
        s << "acceleration of joint " << j << " at waypoint " << i << " is " << a << ", limit "
          << L.acceleration;
        return s.str();
      }
    }
  }
  return "";
}

// ---------------------------------------------------------------------------

struct Planner::Impl {
  RobotModel robot;
  collision::SceneParams scene;
  PlannerParams params;
  std::unique_ptr<KinematicChains> chains;
  std::vector<internal::ClearanceObject> objects;
  std::vector<std::vector<char>> checked;  // [sphere][object]
  std::vector<double> radii;
  std::vector<int> links;
  // Robot spheres grouped by link (for culling waypoints far from the person).
  std::vector<std::vector<int>> link_groups;
  std::vector<int> sphere_group;  // group of each sphere
  int ee_link = -1;
  Eigen::Vector3d ee_offset = Eigen::Vector3d::Zero();
  Eigen::VectorXd lower, upper, vmax, amax;

  // Per attempt (immutable while the optimisers run).
  struct Attempt {
    int nq = 0, n = 0, k = 1, m = 0;
    double dt = 0.1;
    Eigen::MatrixXd base;  // nq x (n+1) initial trajectory (frozen prefix, goal)
    Eigen::VectorXd qdot0, q_goal;
    Eigen::MatrixXd Hinv;  // m x m inverse smoothness Hessian (unweighted)
    std::vector<int> steps;
    const HumanPrediction* prediction = nullptr;
    // Exact bounds of the waypoints no optimiser changes (the frozen prefix
    // 0..k-1 and the goal n; size n+1, free entries unused), computed once
    // per attempt by FixBounds.
    std::vector<double> fixed_bounds;
    double prediction_dt = 0.1, prediction_start = 0.0;
    bool perturb_base = true;
  };

  struct Eval {
    double total = 0.0, smooth = 0.0, obstacle = 0.0, dynamic = 0.0, goal = 0.0, limits = 0.0, separation = 0.0;
    std::vector<collision::WaypointBound> bounds;
  };

  struct Workspace {
    std::vector<RobotData> data;
    std::unique_ptr<collision::TrajectoryBoundWorkspace> bound_ws;
    Eigen::MatrixXd A, V, G;
    std::vector<double> group_log_volume;  // [group * H + human sphere]
    std::vector<int> active;               // free waypoints passed to the bound
    std::vector<char> group_needed;        // link groups passed to the bound
    std::vector<char> far;                 // [group * objects + object]: beyond the margin
    collision::RobotSpheresTrajectory sub;  // their spheres at the active waypoints
    std::vector<int> sub_spheres;          // sphere index of each sub sphere
    std::vector<collision::WaypointBound> active_bounds;
  };

  struct Candidate {
    Eigen::MatrixXd Q;
    double cost = std::numeric_limits<double>::infinity();
    bool static_ok = false;   // limits and clearance
    bool safe = false;        // bound below threshold on non-frozen waypoints
    double max_bound = 0.0;
    double min_clearance = 0.0;
    std::vector<double> bounds;
    int first_unsafe = -1;
    double first_feasible_time = -1.0;
  };

  double Threshold() const { return 1.0 - params.delta_cl; }

  // A ball around one link's spheres at the FK in `data`: centre *c (the
  // spheres' mean) and its radius, which covers every sphere. Distances
  // are 1-Lipschitz, so the ball's distance bounds all its spheres'.
  double LinkBall(const RobotData& data, const std::vector<int>& group, Eigen::Vector3d* c) const {
    c->setZero();
    for (int sp : group) *c += data.p_WS.col(sp);
    *c /= static_cast<double>(group.size());
    double cover = 0.0;
    for (int sp : group) cover = std::max(cover, (data.p_WS.col(sp) - *c).norm() + radii[sp]);
    return cover;
  }

  // Minimum signed distance of all checked spheres at the FK in `data`.
  double Clearance(const RobotData& data) const {
    // Per link, a ball around its spheres first (the signed distance is
    // 1-Lipschitz; 1e-9 against rounding): links that cannot go below the
    // best so far are skipped. The minimum is the same.
    double best = std::numeric_limits<double>::infinity();
    for (const std::vector<int>& grp : link_groups) {
      Eigen::Vector3d c;
      const double cover = LinkBall(data, grp, &c);
      for (int o = 0; o < static_cast<int>(objects.size()); ++o) {
        if (!checked[grp[0]][o]) continue;  // allowed pairs are per link
        const auto& ob = objects[o];
        if ((c - ob.centre_W).norm() - ob.bounding_radius - cover >= best + 1e-9) continue;
        if (internal::PointSignedDistance(ob, c, nullptr) - cover >= best + 1e-9) continue;
        for (int s : grp) {
          const Eigen::Vector3d p = data.p_WS.col(s);
          if ((p - ob.centre_W).norm() - ob.bounding_radius - radii[s] >= best) continue;
          best = std::min(best, internal::PointSignedDistance(ob, p, nullptr) - radii[s]);
        }
      }
    }
    return best;
  }

  void PrepareWorkspace(const Attempt& at, Workspace* ws) const {
    const int W = at.n + 1;
    while (static_cast<int>(ws->data.size()) < W) ws->data.emplace_back(robot);
    if (at.prediction != nullptr) {
      // Only the free waypoints k..n-1 are evaluated: the others never
      // change (FixBounds).
      ws->sub.centres.resize(3, static_cast<Eigen::Index>(at.n - at.k) * radii.size());
      ws->sub.steps.reserve(at.n - at.k);
      ws->sub.radii.reserve(radii.size());
      ws->sub.links.reserve(radii.size());
      ws->sub_spheres.reserve(radii.size());
      ws->active.reserve(at.n - at.k);
      ws->active_bounds.reserve(at.n - at.k);
      if (!ws->bound_ws)
        ws->bound_ws = std::make_unique<collision::TrajectoryBoundWorkspace>(
            static_cast<int>(radii.size()), at.prediction->num_spheres());
      const int H = at.prediction->num_spheres();
      ws->group_log_volume.resize(link_groups.size() * H);
      for (std::size_t g = 0; g < link_groups.size(); ++g) {
        double r = 0.0;
        for (int sp : link_groups[g]) r = std::max(r, radii[sp]);
        for (int l = 0; l < H; ++l)
          ws->group_log_volume[g * H + l] =
              std::log(collision::BallVolume(r + at.prediction->radius(l)));
      }
    }
  }

  // Cost of Q (nq x (n+1)) and, if G != nullptr, its gradient (free columns).
  void Evaluate(const Attempt& at, const Eigen::MatrixXd& Q, Workspace* ws, Eval* ev,
                Eigen::MatrixXd* G) const {
    const CostWeights& w = params.weights;
    const int n = at.n, k = at.k, nq = at.nq;
    const double dt = at.dt;
    ev->smooth = ev->obstacle = ev->dynamic = ev->goal = ev->limits = ev->separation = 0.0;
    if (G) G->setZero(nq, n + 1);
    // Accelerations a_i, i = 0..n, and velocities v_i, i = 0..n-1.
    Eigen::MatrixXd& A = ws->A;
    Eigen::MatrixXd& V = ws->V;
    A.resize(nq, n + 1);
    V.resize(nq, n);
    for (int i = 0; i <= n; ++i) {
      const Eigen::VectorXd prev = i == 0 ? Eigen::VectorXd(Q.col(0) - at.qdot0 * dt)
                                          : Eigen::VectorXd(Q.col(i - 1));
      const Eigen::VectorXd next = i == n ? Eigen::VectorXd(Q.col(n)) : Eigen::VectorXd(Q.col(i + 1));
      A.col(i) = (next - 2.0 * Q.col(i) + prev) / (dt * dt);
      if (i < n) V.col(i) = (Q.col(i + 1) - Q.col(i)) / dt;
    }
    ev->smooth = w.smoothness * dt * A.squaredNorm();
    for (int i = k; i <= n; ++i) ev->goal += w.goal * dt * (Q.col(i) - at.q_goal).squaredNorm();
    if (G) {
      for (int j = k; j < n; ++j) {
        G->col(j) += w.smoothness * (2.0 / dt) * (A.col(j - 1) - 2.0 * A.col(j) + A.col(j + 1));
        G->col(j) += 2.0 * w.goal * dt * (Q.col(j) - at.q_goal);
      }
    }
    // Velocity / acceleration limit penalties (terms touching free waypoints).
    const double scale = params.limit_scale;
    for (int i = std::max(0, k - 1); i < n; ++i) {
      for (int j = 0; j < nq; ++j) {
        const double e = (std::abs(V(j, i)) - scale * vmax[j]) / vmax[j];
        if (e <= 0.0) continue;
        ev->limits += w.limits * e * e;
        if (G) {
          const double d = w.limits * 2.0 * e * (V(j, i) < 0 ? -1.0 : 1.0) / vmax[j] / dt;
          if (i + 1 >= k && i + 1 < n) (*G)(j, i + 1) += d;
          if (i >= k && i < n) (*G)(j, i) -= d;
        }
      }
    }
    for (int i = std::max(0, k - 1); i <= n; ++i) {
      for (int j = 0; j < nq; ++j) {
        const double e = (std::abs(A(j, i)) - scale * amax[j]) / amax[j];
        if (e <= 0.0) continue;
        ev->limits += w.limits * e * e;
        if (G) {
          const double d = w.limits * 2.0 * e * (A(j, i) < 0 ? -1.0 : 1.0) / amax[j] / (dt * dt);
          if (i - 1 >= k && i - 1 < n) (*G)(j, i - 1) += d;
          if (i >= k && i < n) (*G)(j, i) -= 2.0 * d;
          if (i + 1 >= k && i + 1 < n) (*G)(j, i + 1) += d;
        }
      }
    }
    // Forward kinematics of the free waypoints (the only ones the costs use).
    const int S = static_cast<int>(radii.size());
    for (int i = k; i < n; ++i) collision::CalcForwardKinematics(robot, Q.col(i), &ws->data[i]);
    // Static obstacles. Per link, a ball around its spheres first: the
    // signed distance is 1-Lipschitz, so when the ball's centre is farther
    // than its cover radius + margin (+ 1e-9 against rounding) from an
    // object, none of the link's spheres is within the margin of it.
    const double margin = params.obstacle_margin;
    const int NO = static_cast<int>(objects.size());
    const int NG = static_cast<int>(link_groups.size());
    ws->far.resize(static_cast<std::size_t>(NG) * NO);
    for (int i = k; i < n; ++i) {
      const RobotData& d = ws->data[i];
      for (int g = 0; g < NG; ++g) {
        Eigen::Vector3d c;
        const double cover = LinkBall(d, link_groups[g], &c);
        for (int o = 0; o < NO; ++o) {
          const auto& ob = objects[o];
          double lower = (c - ob.centre_W).norm() - ob.bounding_radius - cover;
          if (lower < margin + 1e-9) lower = internal::PointSignedDistance(ob, c, nullptr) - cover;
          ws->far[g * NO + o] = lower >= margin + 1e-9;
        }
      }
      for (int s = 0; s < S; ++s) {
        const Eigen::Vector3d p = d.p_WS.col(s);
        Eigen::Vector3d gp = Eigen::Vector3d::Zero();
        bool any = false;
        for (int o = 0; o < NO; ++o) {
          if (!checked[s][o] || ws->far[sphere_group[s] * NO + o]) continue;
          const auto& ob = objects[o];
          if ((p - ob.centre_W).norm() - ob.bounding_radius - radii[s] >= margin) continue;
          // The normal only for spheres within the margin (the same distance).
          const double dist = internal::PointSignedDistance(ob, p, nullptr) - radii[s];
          if (dist >= margin) continue;
          ev->obstacle += w.obstacle * (margin - dist) * (margin - dist);
          if (!G) continue;
          Eigen::Vector3d n_W;
          internal::PointSignedDistance(ob, p, &n_W);
          gp -= 2.0 * w.obstacle * (margin - dist) * n_W;
          any = true;
        }
        if (G && any) chains->AddPointGradient(d, links[s], p, gp, G->col(i));
      }
    }
    // Dynamic obstacle (the person).
    if (at.prediction) {
      // Bounds of the free waypoints only (ev->bounds[i - k]). Pairs whose
      // upper bound is below tau are not evaluated exactly: a waypoint whose
      // bound is <= tau costs nothing and has no gradient, and one above tau
      // gets the same exact value and argmax pair as with the default
      // (see EvaluateTrajectoryBound's pruning); reported values below tau
      // are upper bounds, which also keeps the safety test (>= 1 - delta_CL
      // > tau) unchanged. Exact values for the result: ExactBounds.
      const double tau = params.dynamic_activation * Threshold();
      collision::TrajectoryBoundParams bp;
      bp.negligible = tau * (1.0 - 1e-9);
      // Waypoints where every pair's level-1 upper bound (the library's
      // first pruning test) is <= negligible contribute nothing; they are
      // recognised per link group (a ball around the link's spheres; every
      // sphere's level-1 bound is at most the group's) and not passed on.
      const HumanPrediction& hp = *at.prediction;
      const int H = hp.num_spheres();
      const double log_negligible = std::log(bp.negligible);
      const double log_psum = std::log(hp.probability_sum());
      ws->active.clear();
      ws->group_needed.assign(link_groups.size(), 0);
      for (int i = k; i < n; ++i) {
        const int t = at.steps[i];
        const RobotData& d = ws->data[i];
        bool may_matter = false;
        for (std::size_t g = 0; g < link_groups.size(); ++g) {
          Eigen::Vector3d c;
          const double cover = LinkBall(d, link_groups[g], &c);
          for (int l = 0; l < H; ++l) {
            const HumanPrediction::Summary& sm = hp.summary(t, l);
            const double delta =
                std::max(0.0, (sm.centre - c).norm() - sm.spread - cover - hp.radius(l));
            const double lu = log_psum + std::min(0.0, ws->group_log_volume[g * H + l] +
                                                           sm.max_log_peak -
                                                           delta * delta * sm.half_inverse_max_eigenvalue);
            if (lu > log_negligible) {
              may_matter = true;
              ws->group_needed[g] = 1;
              break;
            }
          }
        }
        if (may_matter) ws->active.push_back(i);
      }
      const int num_active = static_cast<int>(ws->active.size());
      ev->bounds.assign(n - k, collision::WaypointBound{});
      for (auto& b : ev->bounds) {
        b.bound = bp.negligible;  // an upper bound of the culled waypoints
        b.exact = false;
      }
      if (num_active > 0) {
        // Only the spheres of links that may matter at some active waypoint,
        // in their original order: the others' pairs would all be skipped as
        // negligible, so the maximum and its argmax pair are unchanged.
        collision::RobotSpheresTrajectory& sub = ws->sub;
        ws->sub_spheres.clear();
        sub.radii.clear();
        sub.links.clear();
        for (int sp = 0; sp < S; ++sp) {
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
            sub.centres.col(static_cast<Eigen::Index>(a) * SS + j) =
                ws->data[i].p_WS.col(ws->sub_spheres[j]);
          sub.steps.push_back(at.steps[i]);
        }
        collision::EvaluateTrajectoryBound(hp, sub, bp, ws->bound_ws.get(), &ws->active_bounds);
        for (int a = 0; a < num_active; ++a) {
          collision::WaypointBound b = ws->active_bounds[a];
          if (b.robot_sphere >= 0) b.robot_sphere = ws->sub_spheres[b.robot_sphere];
          ev->bounds[ws->active[a] - k] = b;
        }
      }
      for (int i = k; i < n; ++i) {
        const collision::WaypointBound& wb = ev->bounds[i - k];
        if (wb.bound <= tau) continue;
        ev->dynamic += w.dynamic * (wb.bound - tau) * (wb.bound - tau);
        if (!G || wb.robot_sphere < 0) continue;
        // Gradient of the argmax pair's mixture bound w.r.t. the robot sphere
        // centre b: by the envelope theorem, d log f(x_max)/db equals the
        // density's log-gradient at x_max, -Sigma^-1 (x_max - mu). The
        // mixture's log-gradient weights each action by its share; when the
        // mean lies inside the ball (gradient 0) the direction towards the
        // mean, scaled by 1/s_min, is used instead. The result is scaled by
        // the clamped bound, so it stays bounded when the raw bound exceeds 1.
        const int s = wb.robot_sphere, l = wb.human_sphere, step = at.steps[i];
        const Eigen::Vector3d b = ws->data[i].p_WS.col(s);
        const double R = radii[s] + at.prediction->radius(l);
        Eigen::Vector3d glog = Eigen::Vector3d::Zero();
        double total = 0.0;
        for (int c = 0; c < at.prediction->num_actions(); ++c) {
          const double pc = at.prediction->action_probability(c);
          if (pc <= 0.0) continue;
          const collision::FactorizedGaussian& g = at.prediction->sphere(c, step, l);
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
        if (total <= 0.0) continue;
        glog /= total;
        const Eigen::Vector3d gp = w.dynamic * 2.0 * (wb.bound - tau) * wb.bound * glog;
        chains->AddPointGradient(ws->data[i], links[s], b, gp, G->col(i));
      }
    }
    // Keep-out from the predicted person (PlannerParams::human_separation).
    if (at.prediction && params.human_separation > 0.0) {
      const HumanPrediction& hp = *at.prediction;
      const int H = hp.num_spheres();
      const double D = params.human_separation;
      for (int i = k; i < n; ++i) {
        const RobotData& d = ws->data[i];
        const int t = at.steps[i];
        for (std::size_t g = 0; g < link_groups.size(); ++g) {
          // A ball around the link's spheres first, as for the obstacles.
          Eigen::Vector3d c;
          const double cover = LinkBall(d, link_groups[g], &c);
          for (int l = 0; l < H; ++l) {
            // The bounding ball of the actions' means bounds every mean.
            const HumanPrediction::Summary& sm = hp.summary(t, l);
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
                ev->separation += w.separation * pa * (D - dist) * (D - dist);
                if (!G || len < 1e-9) continue;
                const Eigen::Vector3d gp = -2.0 * w.separation * pa * (D - dist) * diff / len;
                chains->AddPointGradient(d, links[s], p, gp, G->col(i));
              }
            }
          }
        }
      }
    }
    ev->total = ev->smooth + ev->obstacle + ev->dynamic + ev->goal + ev->limits + ev->separation;
  }

  void Project(const Attempt& at, Eigen::MatrixXd* Q) const {
    const double mg = params.position_margin;
    for (int i = at.k; i < at.n; ++i)
      Q->col(i) = Q->col(i).array().max(lower.array() + mg).min(upper.array() - mg).matrix();
  }

  // Static check (limits, clearance at substeps) and bound check.
  void Check(const Attempt& at, const Eval& ev, Workspace* ws, Candidate* c) const {
    const Eigen::MatrixXd& Q = c->Q;
    c->static_ok = CheckLimits(robot, Q, at.dt, at.qdot0).empty();
    double clear = std::numeric_limits<double>::infinity();
    const int sub = params.collision_check_substeps;
    RobotData& d = ws->data[0];
    Eigen::VectorXd q(at.nq);
    for (int i = std::max(0, at.k - 1); i <= at.n && clear >= params.min_clearance; ++i) {
      const int count = i < at.n ? sub : 1;
      for (int s = 0; s < count; ++s) {
        q = Q.col(i) + (static_cast<double>(s) / sub) *
                           (i < at.n ? Eigen::VectorXd(Q.col(i + 1) - Q.col(i))
                                     : Eigen::VectorXd::Zero(at.nq));
        collision::CalcForwardKinematics(robot, q, &d);
        clear = std::min(clear, Clearance(d));
      }
    }
    c->min_clearance = clear;
    c->static_ok = c->static_ok && clear >= params.min_clearance;
    c->bounds.clear();
    c->max_bound = 0.0;
    c->first_unsafe = -1;
    if (at.prediction) {
      c->bounds = at.fixed_bounds;
      for (int i = at.k; i < at.n; ++i) c->bounds[i] = ev.bounds[i - at.k].bound;
      for (int i = at.k; i <= at.n; ++i) {
        c->max_bound = std::max(c->max_bound, c->bounds[i]);
        if (c->first_unsafe < 0 && c->bounds[i] >= Threshold()) c->first_unsafe = i;
      }
    }
    c->safe = c->first_unsafe < 0;
  }

  // Smallest surface distance (m) between the robot's spheres and the
  // predicted human spheres' means (actions with probability >=
  // kSeparationMinProbability) over the waypoints [from, to].
  double HumanSeparation(const Attempt& at, const Eigen::MatrixXd& Q, int from, int to) const {
    double best = std::numeric_limits<double>::infinity();
    const HumanPrediction& hp = *at.prediction;
    RobotData d(robot);
    for (int i = from; i <= to; ++i) {
      collision::CalcForwardKinematics(robot, Q.col(i), &d);
      for (int a = 0; a < hp.num_actions(); ++a) {
        if (hp.action_probability(a) < kSeparationMinProbability) continue;
        for (int l = 0; l < hp.num_spheres(); ++l) {
          const Eigen::Vector3d& mu = hp.sphere(a, at.steps[i], l).mean;
          for (int s = 0; s < static_cast<int>(radii.size()); ++s)
            best = std::min(best, (d.p_WS.col(s) - mu).norm() - radii[s] - hp.radius(l));
        }
      }
    }
    return best;
  }

  // Exact bounds (default TrajectoryBoundParams) of the waypoints [from, to]
  // of Q into (*out)[from..to]; *out must have Q.cols() entries.
  void ExactBounds(const Attempt& at, const Eigen::MatrixXd& Q, int from, int to,
                   std::vector<double>* out) const {
    const int S = static_cast<int>(radii.size());
    collision::RobotSpheresTrajectory rs;
    rs.radii = radii;
    rs.links = links;
    rs.centres.resize(3, static_cast<Eigen::Index>(to - from + 1) * S);
    RobotData d(robot);
    for (int i = from; i <= to; ++i) {
      collision::CalcForwardKinematics(robot, Q.col(i), &d);
      rs.centres.middleCols(static_cast<Eigen::Index>(i - from) * S, S) = d.p_WS;
      rs.steps.push_back(at.steps[i]);
    }
    collision::TrajectoryBoundWorkspace bw(S, at.prediction->num_spheres());
    std::vector<collision::WaypointBound> wb;
    collision::EvaluateTrajectoryBound(*at.prediction, rs, collision::TrajectoryBoundParams{}, &bw,
                                       &wb);
    for (int i = from; i <= to; ++i) (*out)[i] = wb[i - from].bound;
  }

  // Bounds of the frozen prefix and the goal of at->base (unchanged by the
  // optimisers).
  void FixBounds(Attempt* at) const {
    at->fixed_bounds.assign(at->n + 1, 0.0);
    if (!at->prediction) return;
    ExactBounds(*at, at->base, 0, at->k - 1, &at->fixed_bounds);
    ExactBounds(*at, at->base, at->n, at->n, &at->fixed_bounds);
  }

  // One optimiser: initial trajectory from the base (perturbed for o > 0),
  // covariant gradient descent with backtracking, feasibility check.
  // State of one optimiser between rounds (see RunAll).
  struct OptState {
    Eigen::MatrixXd Q, G, G_new, Qn;
    Eval ev, ev_new;
    int iterations = 0;   // accepted iterations so far
    bool started = false;
    bool done = false;    // converged, stuck or at max_iterations
    bool checked = false; // `c` describes the current Q
    Candidate c;
  };

  // Initial trajectory from the base (perturbed for o > 0) and its cost.
  void StartOptimizer(const Attempt& at, int o, std::uint64_t seed, Workspace* ws,
                      OptState* st) const {
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
  void IterateOptimizer(const Attempt& at, int until, Workspace* ws, OptState* st) const {
    const double inv_ws = 1.0 / params.weights.smoothness;
    until = std::min(until, params.max_iterations);
    while (!st->done && st->iterations < until) {
      const Eigen::MatrixXd D = st->G.middleCols(at.k, at.m) * at.Hinv * inv_ws;
      double alpha = params.step_size;
      bool accepted = false;
      for (int ls = 0; ls < 6; ++ls) {
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
  void CheckOptimizer(const Attempt& at, Workspace* ws, OptState* st, Clock::time_point t0) const {
    if (st->checked) return;
    Candidate& c = st->c;
    c.Q = st->Q;
    c.cost = st->ev.total;
    Check(at, st->ev, ws, &c);
    if (c.static_ok && c.safe && c.first_feasible_time < 0.0)
      c.first_feasible_time = Seconds(t0, Clock::now());
    st->checked = true;
  }

  // Runs the optimisers on up to num_threads threads. With
  // early_stop_interval = K > 0 they advance in rounds of K iterations; after
  // each round (all optimisers at the same iteration budget) every optimiser
  // is checked, and if one is feasible and safe all stop. The decision uses
  // only the optimisers' states at the round's end, never the order in which
  // threads finish, so the result is the same for any thread count. K = 0:
  // one round, every optimiser runs to convergence.
  std::vector<Candidate> RunAll(const Attempt& at, int num_opt, int num_threads,
                                std::uint64_t seed, Clock::time_point t0) const {
    const int workers = std::max(1, std::min(num_threads <= 0 ? num_opt : num_threads, num_opt));
    const int K = params.early_stop_interval > 0 ? params.early_stop_interval : params.max_iterations;
    std::vector<OptState> st(num_opt);
    std::vector<Workspace> wss(workers);
    for (auto& ws : wss) PrepareWorkspace(at, &ws);
    for (int round = 1;; ++round) {
      const int until = round * K;
      std::atomic<int> next{0};
      auto work = [&](int t) {
        Workspace* ws = &wss[t];
        for (int o = next.fetch_add(1); o < num_opt; o = next.fetch_add(1)) {
          OptState& s = st[o];
          if (!s.started) StartOptimizer(at, o, seed, ws, &s);
          IterateOptimizer(at, until, ws, &s);
          CheckOptimizer(at, ws, &s, t0);
        }
      };
      if (workers == 1) {
        work(0);
      } else {
        std::vector<std::thread> threads;
        for (int t = 0; t < workers; ++t) threads.emplace_back(work, t);
        for (auto& t : threads) t.join();
      }
      bool all_done = true, any_ok = false;
      for (const auto& s : st) {
        all_done = all_done && s.done;
        any_ok = any_ok || (s.c.static_ok && s.c.safe);
      }
      if (all_done || any_ok || until >= params.max_iterations) break;
    }
    std::vector<Candidate> out(num_opt);
    for (int o = 0; o < num_opt; ++o) out[o] = std::move(st[o].c);
    return out;
  }

  void BuildSmoothness(Attempt* at) const {
    const int m = at->m;
    // K: rows a_{k-1}..a_n, columns free waypoints k..n-1 (second differences).
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m, m);
    for (int i = at->k - 1; i <= at->n; ++i) {
      // coefficients of q_{i-1}, q_i, q_{i+1} in dt^2 a_i
      const int idx[3] = {i - 1, i, i + 1};
      const double cf[3] = {1.0, -2.0, 1.0};
      for (int a = 0; a < 3; ++a) {
        const int fa = idx[a] - at->k;
        if (fa < 0 || fa >= m) continue;
        for (int b = 0; b < 3; ++b) {
          const int fb = idx[b] - at->k;
          if (fb < 0 || fb >= m) continue;
          H(fa, fb) += cf[a] * cf[b];
        }
      }
    }
    H *= 2.0 / (at->dt * at->dt * at->dt);
    at->Hinv = H.llt().solve(Eigen::MatrixXd::Identity(m, m));
  }

  void SetSteps(Attempt* at) const {
    at->steps.assign(at->n + 1, 0);
    if (!at->prediction) return;
    const int last = at->prediction->num_steps() - 1;
    for (int i = 0; i <= at->n; ++i) {
      const double s = std::round((i * at->dt - at->prediction_start) / at->prediction_dt);
      at->steps[i] = static_cast<int>(std::clamp(s, 0.0, static_cast<double>(last)));
    }
  }
};

// ---------------------------------------------------------------------------

Planner::Planner(RobotModel robot, collision::SceneParams scene, PlannerParams params)
    : impl_(std::make_unique<Impl>()) {
  if (const std::string why = params.Validate(); !why.empty())
    throw std::invalid_argument("PlannerParams: " + why);
  if (const std::string why = scene.Validate(); !why.empty())
    throw std::invalid_argument("SceneParams: " + why);
  Impl& I = *impl_;
  I.robot = std::move(robot);
  I.scene = std::move(scene);
  I.params = std::move(params);
  if (I.robot.nq < 1) throw std::invalid_argument("Planner: robot has no joints");
  I.chains = std::make_unique<KinematicChains>(I.robot);
  I.ee_link = I.robot.FindLink(I.params.end_effector_link);
  if (I.ee_link < 0)
    throw std::invalid_argument("Planner: unknown end_effector_link '" +
                                I.params.end_effector_link + "'");
  I.ee_offset = Eigen::Vector3d(I.params.end_effector_offset[0], I.params.end_effector_offset[1],
                                I.params.end_effector_offset[2]);
  for (const auto& o : I.scene.objects) I.objects.push_back(internal::MakeClearanceObject(o));
  for (const auto& s : I.robot.spheres) {
    I.radii.push_back(s.radius);
    I.links.push_back(s.link);
  }
  for (std::size_t s = 0; s < I.radii.size(); ++s) {
    auto g = std::find_if(I.link_groups.begin(), I.link_groups.end(),
                          [&](const std::vector<int>& v) { return I.links[v[0]] == I.links[s]; });
    if (g == I.link_groups.end())
      I.link_groups.push_back({static_cast<int>(s)});
    else
      g->push_back(static_cast<int>(s));
  }
  I.sphere_group.assign(I.radii.size(), 0);
  for (std::size_t g = 0; g < I.link_groups.size(); ++g)
    for (int s : I.link_groups[g]) I.sphere_group[s] = static_cast<int>(g);
  I.checked.assign(I.radii.size(), std::vector<char>(I.objects.size(), 1));
  for (const auto& [link_name, object_name] : I.params.allowed_collisions) {
    const int link = I.robot.FindLink(link_name);
    if (link < 0)
      throw std::invalid_argument("Planner: allowed_collisions names unknown link '" + link_name +
                                  "'");
    int object = -1;
    for (int o = 0; o < static_cast<int>(I.scene.objects.size()); ++o)
      if (I.scene.objects[o].name == object_name) object = o;
    if (object < 0) continue;  // scenes without this object: nothing to allow
    for (std::size_t s = 0; s < I.radii.size(); ++s)
      if (I.links[s] == link) I.checked[s][object] = 0;
  }
  const int nq = I.robot.nq;
  I.lower = I.robot.LowerLimits();
  I.upper = I.robot.UpperLimits();
  I.vmax.resize(nq);
  I.amax.resize(nq);
  for (int j = 0; j < nq; ++j) {
    const auto& L = I.robot.joints[I.robot.q_joints[j]].limits;
    if (!(L.velocity > 0.0) || !(L.acceleration > 0.0))
      throw std::invalid_argument("Planner: joint " + std::to_string(j) +
                                  " needs positive velocity and acceleration limits");
    I.vmax[j] = L.velocity;
    I.amax[j] = L.acceleration;
  }
}

Planner::~Planner() = default;

const RobotModel& Planner::robot() const { return impl_->robot; }
const PlannerParams& Planner::params() const { return impl_->params; }

IkResult Planner::SolveIk(const Eigen::Vector3d& p_WE, const Eigen::Quaterniond& R_WE,
                          const Eigen::VectorXd& q_seed, std::uint64_t seed) const {
  const Impl& I = *impl_;
  if (!p_WE.allFinite() || !R_WE.coeffs().allFinite() || std::abs(R_WE.norm() - 1.0) > 1e-3)
    throw std::invalid_argument("SolveIk: goal pose must be finite with a unit quaternion, got p " +
                                Vec(p_WE) + ", q (x,y,z,w) " + Vec(R_WE.coeffs()));
  IkOptions opt;
  opt.max_iterations = I.params.ik_max_iterations;
  opt.damping = I.params.ik_damping;
  opt.position_tolerance = I.params.ik_position_tolerance;
  opt.orientation_tolerance = I.params.ik_orientation_tolerance;
  opt.restarts = I.params.ik_restarts;
  opt.position_margin = I.params.position_margin;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R_WE.normalized().toRotationMatrix();
  X.translation() = p_WE;
  std::mt19937_64 rng(SplitMix(seed));
  return planning::SolveIk(*I.chains, I.ee_link, I.ee_offset, X, q_seed, opt, &rng);
}

double Planner::CalcClearance(const Eigen::VectorXd& q) const {
  if (q.size() != impl_->robot.nq || !q.allFinite())
    throw std::invalid_argument("CalcClearance: q must have " + std::to_string(impl_->robot.nq) +
                                " finite values, got " + Vec(q));
  RobotData d(impl_->robot);
  collision::CalcForwardKinematics(impl_->robot, q, &d);
  return impl_->Clearance(d);
}

std::vector<int> Planner::CheckedSpheres(int object) const {
  std::vector<int> out;
  for (std::size_t s = 0; s < impl_->radii.size(); ++s)
    if (impl_->checked[s].at(object)) out.push_back(static_cast<int>(s));
  return out;
}

Eigen::MatrixXd Planner::ShiftTrajectory(const Eigen::MatrixXd& previous, double dt,
                                         double elapsed) {
  if (previous.cols() < 1) throw std::invalid_argument("ShiftTrajectory: empty trajectory");
  if (!(dt > 0.0) || !(elapsed >= 0.0) || !std::isfinite(elapsed))
    throw std::invalid_argument("ShiftTrajectory: need dt > 0 and finite elapsed >= 0, got dt " +
                                std::to_string(dt) + ", elapsed " + std::to_string(elapsed));
  const Eigen::Index shift = static_cast<Eigen::Index>(std::llround(elapsed / dt));
  Eigen::MatrixXd out(previous.rows(), previous.cols());
  for (Eigen::Index i = 0; i < previous.cols(); ++i)
    out.col(i) = previous.col(std::min(i + shift, previous.cols() - 1));
  return out;
}

PlanningResult Planner::Plan(const PlanningRequest& request) const {
  return Plan(request, impl_->params.num_optimizers, impl_->params.num_threads,
              impl_->params.seed);
}

PlanningResult Planner::Plan(const PlanningRequest& req, int num_optimizers, int num_threads,
                             std::uint64_t seed) const {
  const auto t0 = Clock::now();
  const Impl& I = *impl_;
  const PlannerParams& P = I.params;
  const int nq = I.robot.nq;
  auto bad = [](const std::string& what) { throw std::invalid_argument("Plan: " + what); };
  if (num_optimizers < 1) bad("num_optimizers must be >= 1, got " + std::to_string(num_optimizers));
  if (num_threads < 0) bad("num_threads must be >= 0, got " + std::to_string(num_threads));
  if (req.start_q.size() != nq)
    bad("start has " + std::to_string(req.start_q.size()) + " joint values, the robot has " +
        std::to_string(nq));
  if (!req.start_q.allFinite()) bad("start is not finite: " + Vec(req.start_q));
  const double tol = 1e-9;
  for (int j = 0; j < nq; ++j)
    if (req.start_q[j] < I.lower[j] - tol || req.start_q[j] > I.upper[j] + tol)
      bad("start joint " + std::to_string(j) + " = " + std::to_string(req.start_q[j]) +
          " is outside [" + std::to_string(I.lower[j]) + ", " + std::to_string(I.upper[j]) + "]");
  Eigen::VectorXd qdot0 = Eigen::VectorXd::Zero(nq);
  if (req.start_qdot.size() != 0) {
    if (req.start_qdot.size() != nq || !req.start_qdot.allFinite())
      bad("start velocity must have " + std::to_string(nq) + " finite values, got " +
          Vec(req.start_qdot));
    qdot0 = req.start_qdot;
  }
  if (req.num_frozen < 1) bad("num_frozen must be >= 1, got " + std::to_string(req.num_frozen));
  if (req.warm_start.size() != 0) {
    if (req.warm_start.rows() != nq || !req.warm_start.allFinite())
      bad("warm_start must be " + std::to_string(nq) + " x m and finite");
    if ((req.warm_start.col(0) - req.start_q).cwiseAbs().maxCoeff() > 1e-9)
      bad("warm_start column 0 must equal the start " + Vec(req.start_q) + ", got " +
          Vec(req.warm_start.col(0)));
  }
  if (req.num_frozen > 1 && req.warm_start.cols() < req.num_frozen)
    bad("num_frozen = " + std::to_string(req.num_frozen) + " needs a warm_start with as many columns");
  if (req.prediction) {
    if (!(req.prediction_dt > 0.0) || !std::isfinite(req.prediction_dt))
      bad("prediction_dt must be > 0, got " + std::to_string(req.prediction_dt));
    if (!std::isfinite(req.prediction_start))
      bad("prediction_start must be finite, got " + std::to_string(req.prediction_start));
  }

  PlanningResult result;
  result.dt = P.dt;
  // Goal configuration.
  Eigen::VectorXd q_goal;
  if (req.goal.kind == Goal::Kind::kJoint) {
    if (req.goal.q.size() != nq)
      bad("goal has " + std::to_string(req.goal.q.size()) + " joint values, the robot has " +
          std::to_string(nq));
    if (!req.goal.q.allFinite()) bad("goal is not finite: " + Vec(req.goal.q));
    for (int j = 0; j < nq; ++j)
      if (req.goal.q[j] < I.lower[j] || req.goal.q[j] > I.upper[j])
        bad("goal joint " + std::to_string(j) + " = " + std::to_string(req.goal.q[j]) +
            " is outside [" + std::to_string(I.lower[j]) + ", " + std::to_string(I.upper[j]) + "]");
    q_goal = req.goal.q;
  } else {
    const Eigen::VectorXd ik_seed = req.warm_start.cols() > 1
                                        ? Eigen::VectorXd(req.warm_start.col(req.warm_start.cols() - 1))
                                        : req.start_q;
    const IkResult ik = SolveIk(req.goal.p_WE, req.goal.R_WE, ik_seed, seed);
    if (!ik.success) {
      result.status = PlanStatus::kIkFailed;
      std::ostringstream s;
      s << "no IK solution for the goal pose: best position error " << ik.position_error
        << " m, orientation error " << ik.orientation_error << " rad";
      result.reason = s.str();
      result.planning_time = Seconds(t0, Clock::now());
      return result;
    }
    q_goal = ik.q;
  }
  result.goal_q = q_goal;
  if (const double c = CalcClearance(q_goal); c < P.min_clearance) {
    result.status = PlanStatus::kGoalInCollision;
    result.reason = "goal configuration has clearance " + std::to_string(c) + " m < " +
                    std::to_string(P.min_clearance) + " m";
    result.planning_time = Seconds(t0, Clock::now());
    return result;
  }

  // First attempt.
  Impl::Attempt at;
  at.nq = nq;
  at.dt = P.dt;
  const int horizon_n = std::max(2, static_cast<int>(std::lround(P.horizon / P.dt)));
  at.n = horizon_n;
  // A warm start longer than the horizon (it contains earlier waits) keeps
  // its length, up to twice the horizon, so its remaining motion is not cut.
  if (req.warm_start.cols() - 1 > at.n)
    at.n = std::min(static_cast<int>(req.warm_start.cols()) - 1, 2 * at.n);
  // A motion longer than the horizon allows within the velocity limits gets
  // the time it needs after the frozen prefix, up to twice the horizon, and a
  // straight line to the goal as its start; otherwise every attempt would
  // break a velocity limit and the robot would never leave (measured on the
  // Panda: 2.1 rad of joint 1 plans in a 1.5 s horizon, 2.8 rad does not).
  const bool warm_prefix = req.warm_start.cols() > 1;
  const int keep = warm_prefix ? req.num_frozen : 1;
  const Eigen::VectorXd from = warm_prefix ? Eigen::VectorXd(req.warm_start.col(keep - 1)) : req.start_q;
  double t_min = 0.0;
  for (int j = 0; j < nq; ++j) t_min = std::max(t_min, std::abs(q_goal[j] - from[j]) / I.vmax[j]);
  const int need = (keep - 1) + static_cast<int>(std::ceil(kRestToRestPeakFactor * t_min / P.dt));
  bool stretched = false;
  if (need > at.n) {
    at.n = std::min(need, 2 * horizon_n);
    stretched = true;
  }
  at.k = req.num_frozen;
  if (at.k >= at.n) bad("num_frozen = " + std::to_string(at.k) + " leaves no free waypoint in a horizon of " +
                        std::to_string(at.n) + " intervals");
  at.qdot0 = qdot0;
  at.q_goal = q_goal;
  at.prediction = req.prediction;
  at.prediction_dt = req.prediction_dt;
  at.prediction_start = req.prediction_start;
  at.base.resize(nq, at.n + 1);
  const bool warm = req.warm_start.cols() > 1;
  if (warm && stretched) {
    // The frozen prefix, then straight to the goal over the stretched time.
    const int steps = at.n - (keep - 1);
    for (int i = 0; i < keep; ++i) at.base.col(i) = req.warm_start.col(i);
    for (int i = 1; i <= steps; ++i) {
      const double s = static_cast<double>(i) / steps;
      at.base.col(keep - 1 + i) = (1.0 - s) * from + s * q_goal;
    }
  } else if (warm) {
    for (int i = 0; i <= at.n; ++i)
      at.base.col(i) = req.warm_start.col(std::min<Eigen::Index>(i, req.warm_start.cols() - 1));
  } else {
    at.base.col(0) = req.start_q;
    for (int i = 1; i <= at.n; ++i) {
      const double s = static_cast<double>(i) / at.n;
      at.base.col(i) = (1.0 - s) * req.start_q + s * q_goal;
    }
  }
  at.base.col(0) = req.start_q;
  at.base.col(at.n) = q_goal;
  const double wait_steps_d = std::round(P.wait_duration / P.dt);
  const int wait_steps = std::max(1, static_cast<int>(wait_steps_d));

  Impl::Candidate best_fail;
  bool have_fail = false;
  bool any_static = false;
  for (int attempt = 0;; ++attempt) {
    at.m = at.n - at.k;
    I.BuildSmoothness(&at);
    I.SetSteps(&at);
    if (!warm || attempt > 0) {
      // Smoothest trajectory through the frozen prefix and goal: one Newton
      // step on the (quadratic) smoothness from the interpolated base.
      // Skipped for the initial warm start, whose shape is kept.
      if (attempt == 0) {
        Eigen::MatrixXd G;
        // Smoothness gradient only: computed directly.
        Eigen::MatrixXd A(nq, at.n + 1);
        for (int i = 0; i <= at.n; ++i) {
          const Eigen::VectorXd prev = i == 0 ? Eigen::VectorXd(at.base.col(0) - qdot0 * P.dt)
                                              : Eigen::VectorXd(at.base.col(i - 1));
          const Eigen::VectorXd next = i == at.n ? Eigen::VectorXd(at.base.col(at.n))
                                                 : Eigen::VectorXd(at.base.col(i + 1));
          A.col(i) = (next - 2.0 * at.base.col(i) + prev) / (P.dt * P.dt);
        }
        G.setZero(nq, at.m);
        for (int j = at.k; j < at.n; ++j)
          G.col(j - at.k) = (2.0 / P.dt) * (A.col(j - 1) - 2.0 * A.col(j) + A.col(j + 1));
        at.base.middleCols(at.k, at.m) -= G * at.Hinv;
        I.Project(at, &at.base);
      }
    }
    I.FixBounds(&at);
    std::vector<Impl::Candidate> cands = I.RunAll(at, num_optimizers, num_threads, seed, t0);
    int win = -1, num_ok = 0;
    int ref = -1;  // lowest-cost statically feasible candidate
    double first_time = -1.0;
    for (int o = 0; o < num_optimizers; ++o) {
      const auto& c = cands[o];
      if (c.static_ok && c.safe) {
        ++num_ok;
        if (first_time < 0.0 || c.first_feasible_time < first_time) first_time = c.first_feasible_time;
        if (win < 0 || c.cost < cands[win].cost) win = o;
      }
      if (c.static_ok && (ref < 0 || c.cost < cands[ref].cost)) ref = o;
    }
    any_static = any_static || ref >= 0;
    auto fill = [&](const Impl::Candidate& c) {
      result.positions = c.Q;
      result.cost = c.cost;
      result.max_bound = c.max_bound;
      result.bounds = c.bounds;
      result.min_clearance = c.min_clearance;
      result.num_frozen = at.k;
    };
    if (win >= 0) {
      fill(cands[win]);
      result.success = true;
      result.status = result.num_waits > 0 ? PlanStatus::kSuccessAfterWait : PlanStatus::kSuccess;
      result.winning_optimizer = win;
      result.num_feasible = num_ok;
      result.time_to_first_feasible = first_time;
      break;
    }
    // Remember the best failure (lowest cost, statically feasible preferred).
    {
      int pick = ref;
      if (pick < 0)
        for (int o = 0; o < num_optimizers; ++o)
          if (pick < 0 || cands[o].cost < cands[pick].cost) pick = o;
      best_fail = cands[pick];
      have_fail = true;
      result.winning_optimizer = pick;
    }
    const bool waiting_can_help = at.prediction != nullptr;
    if (!waiting_can_help || result.num_waits >= P.max_waits) break;

    // Insert a wait: hold the last safe pose q_j of the reference candidate
    // (or the end of the frozen prefix) for wait_steps waypoints.
    int j = at.k - 1;
    Eigen::MatrixXd src = at.base;
    if (ref >= 0) {
      const auto& c = cands[ref];
      src = c.Q;
      const int start = (c.first_unsafe < 0 ? at.n : c.first_unsafe) - 1;
      j = at.k - 1;
      Impl::Workspace ws;
      for (int cand = start; cand > at.k - 1; --cand) {
        // The robot must be able to stop at q_cand within the acceleration limits.
        const Eigen::VectorXd stop_acc = (c.Q.col(cand - 1) - c.Q.col(cand)) / (P.dt * P.dt);
        if ((stop_acc.cwiseAbs().array() > I.amax.array()).any()) continue;
        // Holding q_cand must stay safe during the wait.
        Impl::Attempt hold = at;
        hold.n = cand + wait_steps;
        hold.steps.clear();
        I.SetSteps(&hold);
        I.PrepareWorkspace(hold, &ws);
        RobotData d(I.robot);
        collision::CalcForwardKinematics(I.robot, c.Q.col(cand), &d);
        const int S = static_cast<int>(I.radii.size());
        collision::RobotSpheresTrajectory rs;
        rs.radii = I.radii;
        rs.links = I.links;
        rs.centres.resize(3, static_cast<Eigen::Index>(wait_steps) * S);
        for (int w = 0; w < wait_steps; ++w) {
          rs.centres.middleCols(static_cast<Eigen::Index>(w) * S, S) = d.p_WS;
          rs.steps.push_back(hold.steps[cand + 1 + w]);
        }
        collision::TrajectoryBoundWorkspace bw(S, at.prediction->num_spheres());
        std::vector<collision::WaypointBound> out;
        collision::EvaluateTrajectoryBound(*at.prediction, rs, collision::TrajectoryBoundParams{},
                                           &bw, &out);
        bool safe = true;
        for (const auto& b : out) safe = safe && b.bound < I.Threshold();
        if (safe) {
          j = cand;
          break;
        }
      }
    }
    Eigen::MatrixXd next(nq, at.n + 1 + wait_steps);
    next.leftCols(j + 1) = src.leftCols(j + 1);
    for (int w = 0; w < wait_steps; ++w) next.col(j + 1 + w) = src.col(j);
    next.rightCols(at.n - j) = src.rightCols(at.n - j);
    next.col(next.cols() - 1) = q_goal;
    at.base = next;
    at.n += wait_steps;
    at.k = j + 1 + wait_steps;
    ++result.num_waits;
    result.delay += wait_steps * P.dt;
  }
  if (!result.success && have_fail) {
    result.positions = best_fail.Q;
    result.cost = best_fail.cost;
    result.max_bound = best_fail.max_bound;
    result.bounds = best_fail.bounds;
    result.min_clearance = best_fail.min_clearance;
    result.num_frozen = at.k;
    if (any_static && at.prediction) {
      result.status = PlanStatus::kNoSafeTrajectory;
      std::ostringstream s;
      s << "no trajectory kept the bound below " << I.Threshold() << " after " << result.num_waits
        << " waits; best max bound " << best_fail.max_bound;
      result.reason = s.str();
    } else {
      result.status = PlanStatus::kInfeasible;
      const std::string lim = CheckLimits(I.robot, best_fail.Q, P.dt, qdot0);
      std::ostringstream s;
      s << "no trajectory satisfied the limits and the static clearance; best: "
        << (lim.empty() ? "limits ok" : lim) << ", clearance " << best_fail.min_clearance << " m";
      result.reason = s.str();
    }
  }
  // The optimisers' bounds below the dynamic cost's activation are upper
  // bounds (see Evaluate); report exact values for the returned trajectory.
  if (at.prediction && result.positions.cols() == at.n + 1) {
    I.ExactBounds(at, result.positions, 0, at.n, &result.bounds);
    result.max_bound = 0.0;
    for (int i = at.k; i <= at.n; ++i) result.max_bound = std::max(result.max_bound, result.bounds[i]);
    result.human_separation = I.HumanSeparation(at, result.positions, at.k, at.n - 1);
  }
  result.planning_time = Seconds(t0, Clock::now());
  return result;
}

}  // namespace iplan::planning

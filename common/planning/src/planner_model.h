// The planner's pieces (METHOD.md section 5), internal to iplan::planning:
//
//   PlannerModel   the immutable problem data: robot spheres and limits,
//                  scene objects, allowed pairs, link groups  (planner_model.cc)
//   Problem        one attempt: waypoints, frozen prefix, goal, smoothness
//                  metric, prediction steps                   (problem.cc)
//   cost terms     smoothness, goal, limits, obstacle, dynamic (the bound),
//                  separation: one function per term, value and gradient
//                  into a Workspace                           (cost_terms.cc, dynamic_cost.cc)
//   optimiser      ITOMP's covariant gradient descent with projection and
//                  backtracking, and the feasibility check    (itomp_optimizer.cc)
//   multi-start    N seeded optimisers in rounds, winner selection (multi_start.cc)
//   waits          wait insertion when no safe trajectory exists (wait_insertion.cc)
//
// Planner::Plan (planner.cc) orchestrates them. Units: rad, s, m; positions
// in the world frame W. Thread-safety: PlannerModel and Problem are
// read-only while optimisers run; each thread has its own Workspace.
#pragma once

#include <chrono>
#include <functional>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "clearance.h"
#include "iplan/safety/ssm.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/scene.h"
#include "iplan/collision/trajectory_bound.h"
#include "iplan/planning/kinematics.h"
#include "iplan/planning/planner.h"
#include "iplan/planning/planner_params.h"

namespace iplan::planning::internal {

using Clock = std::chrono::steady_clock;

// Actions predicted with less probability than this do not shape the
// keep-out (PlannerParams::human_separation); each other action's mean
// weighs in with its probability.
constexpr double kSeparationMinProbability = 0.3;
// Peak over mean joint speed of the rest-to-rest motions the optimiser finds
// within the velocity limits: a motion whose largest joint distance over its
// velocity limit is t_min gets at least this times t_min.
constexpr double kRestToRestPeakFactor = 1.5;
// Free waypoints a plan keeps at least when it is shortened to keep its
// warm start's arrival or to fit its motion (PlannerParams::keep_arrival,
// motion_speed_fraction).
constexpr int kMinKeptArrivalFree = 3;
// m: the ssm cost's band above the margin never shrinks below this (or
// ssm_activation - ssm_margin, if smaller) with PlanningRequest::ssm_scale,
// so that plans near the margin are still pushed back from it.
constexpr double kMinSsmBand = 0.02;

std::uint64_t SplitMix(std::uint64_t x);
double Seconds(Clock::time_point a, Clock::time_point b);
std::string VectorText(const Eigen::VectorXd& v);

/// One attempt of Plan: the trajectory's shape and what stays fixed.
struct Problem {
  int nq = 0, n = 0, k = 1, m = 0;  // joints, intervals, frozen prefix, free waypoints (n - k)
  double dt = 0.1;                  // s
  Eigen::MatrixXd base;  // nq x (n+1) initial trajectory (frozen prefix, goal)
  Eigen::VectorXd qdot0, q_goal;
  Eigen::MatrixXd Hinv;  // m x m inverse smoothness Hessian (unweighted)
  // One predicted person: the prediction and the step of each waypoint (planner.h).
  struct Person {
    const collision::HumanPrediction* prediction = nullptr;
    double time_step = 0.1, start = 0.0;  // s
    std::vector<int> steps;
  };
  std::vector<Person> people;  // empty: nobody
  // PlanningRequest::obstacles, checked against every robot sphere; their
  // object indices follow the scene's (PlannerModel::NumObjects).
  std::vector<ClearanceObject> obstacles;
  // Exact bounds of the waypoints no optimiser changes (the frozen prefix
  // 0..k-1 and the goal n; size n+1, free entries unused), computed once
  // per attempt by FixBounds.
  std::vector<double> fixed_bounds;
  bool perturb_base = true;
  // First waypoint judged by the separation monitor's rule: the request's
  // frozen prefix is executing already; waits inserted after it are judged.
  int ssm_from = 1;
  // m, the margin above S_p a safe plan keeps and the one below which the
  // ssm cost starts (PlannerParams, scaled by PlanningRequest::ssm_scale).
  double ssm_margin = 0.0, ssm_activation = 0.0;
  // Wall time at which the optimisers stop (PlanningRequest::time_budget);
  // time_point::max() without a budget.
  Clock::time_point deadline = Clock::time_point::max();
  bool OutOfTime() const { return deadline != Clock::time_point::max() && Clock::now() >= deadline; }
};

/// Cost terms of one trajectory (PlannerParams::weights applied).
struct CostTerms {
  double total = 0.0, smooth = 0.0, obstacle = 0.0, dynamic = 0.0, goal = 0.0, limits = 0.0, separation = 0.0,
         ssm = 0.0;
  std::vector<collision::WaypointBound> bounds;  // free waypoints k..n-1 (dynamic term)
};

/// Where a sphere pair judged by the separation monitor's rule is
/// (ssm_cost.cc): waypoint, person, action and robot sphere.
struct SsmVisit {
  int waypoint = 0, person = 0, action = 0, sphere = 0;
  double probability = 0.0;  // the action's
  bool retreat = false;      // the robot sphere moves away fast enough
};
/// A pair within the ssm cost's activation band.
struct SsmNearPair {
  SsmVisit at;
  Eigen::Vector3d delta;  // robot - human sphere centre (m, W)
  safety::SsmPair pair;
};

/// Scratch space of one thread.
struct Workspace {
  std::vector<SsmNearPair> ssm_near;         // AddSsmCost's pairs
  std::vector<std::uint64_t> ssm_actions;    // [waypoint * persons + person]: their actions (bits)
  std::vector<safety::SsmPair> ssm_tightest;   // JudgeSsm: the tightest violating pair there
  std::vector<collision::RobotData> data;
  std::unique_ptr<collision::TrajectoryBoundWorkspace> bound_ws;
  Eigen::MatrixXd A, V, G;
  std::vector<std::vector<double>> group_log_volume;  // [person][group * H + human sphere]
  std::vector<std::vector<collision::WaypointBound>> person_bounds;  // [person][free waypoint], several people
  std::vector<double> shares;            // [person]: one waypoint's bounds
  std::vector<double> culled_log_bound;  // [free waypoint]: log of the level-1 bound (FindActiveWaypoints)
  std::vector<int> active;               // free waypoints passed to the bound
  std::vector<char> group_needed;        // link groups passed to the bound
  std::vector<char> far;                 // [group * objects + object]: beyond the margin
  collision::RobotSpheresTrajectory sub;  // their spheres at the active waypoints
  std::vector<int> sub_spheres;          // sphere index of each sub sphere
  std::vector<collision::WaypointBound> active_bounds;
};

/// A trajectory judged by the separation monitor's rule (ssm_cost.cc).
struct SsmJudgement {
  double min_margin = std::numeric_limits<double>::infinity();  // m, smallest d - S_p of the non-retreating pairs
  int first_violation = -1;  // first waypoint with a pair below ssm_margin, -1: none
  safety::SsmPair violation;   // its tightest pair
  double stop_probability = 0.0;  // of the actions stopped there
  bool ok() const { return first_violation < 0; }
};

/// A checked trajectory of one optimiser.
struct Candidate {
  Eigen::MatrixXd Q;
  double cost = std::numeric_limits<double>::infinity();
  bool static_ok = false;   // limits and clearance
  bool safe = false;        // bound below threshold on non-frozen waypoints
  double max_bound = 0.0;
  double min_clearance = 0.0;
  std::vector<double> bounds;
  int first_unsafe = -1;
  SsmJudgement ssm;         // the monitor's rule (PlannerParams::predict_ssm); part of `safe`
  double first_feasible_time = -1.0;
};

/// State of one optimiser between rounds (see RunOptimizers).
struct OptimizerState {
  Eigen::MatrixXd Q, G, G_new, Qn;
  CostTerms ev, ev_new;
  int iterations = 0;   // accepted iterations so far
  bool started = false;
  bool done = false;    // converged, stuck or at max_iterations
  bool checked = false; // `c` describes the current Q
  Candidate c;
};

/// Which candidates won one round of optimisers.
struct Selection {
  int winner = -1;          // lowest-cost feasible and safe candidate
  int reference = -1;       // lowest-cost statically feasible candidate
  int num_feasible = 0;     // feasible and safe
  double first_feasible_time = -1.0;
};

/// The robot-neutral link names of a planner file made `robot`'s:
/// end_effector_link "" becomes its tool_link (else its last link), the link
/// "<base>" of allowed_collisions its first two links with spheres.
PlannerParams ResolveRobotLinks(PlannerParams params, const collision::RobotModel& robot);

struct PlannerModel {
  collision::RobotModel robot;
  collision::SceneParams scene;
  PlannerParams params;
  std::unique_ptr<KinematicChains> chains;
  std::vector<ClearanceObject> objects;
  std::vector<std::vector<char>> checked;  // [sphere][object]
  std::vector<double> radii;
  std::vector<int> links;
  // Robot spheres grouped by link (for culling waypoints far from the person).
  std::vector<std::vector<int>> link_groups;
  std::vector<int> sphere_group;  // group of each sphere
  int ee_link = -1;
  Eigen::Vector3d ee_offset = Eigen::Vector3d::Zero();
  Eigen::VectorXd lower, upper, vmax, amax;

  /// Validates and preprocesses. @throws std::invalid_argument (planner.h).
  PlannerModel(collision::RobotModel robot, collision::SceneParams scene, PlannerParams params);

  double Threshold() const { return 1.0 - params.delta_cl; }
  // A ball around one link's spheres at the FK in `data`: centre *c (the
  // spheres' mean) and its radius, which covers every sphere. Distances
  // are 1-Lipschitz, so the ball's distance bounds all its spheres'.
  double LinkBall(const collision::RobotData& data, const std::vector<int>& group, Eigen::Vector3d* c) const;
  // Minimum signed distance of all checked spheres at the FK in `data` to
  // the scene and to `obstacles` (may be null; every sphere is checked).
  double Clearance(const collision::RobotData& data, const std::vector<ClearanceObject>* obstacles = nullptr) const;
  // The scene's objects, then the attempt's obstacles, by one index.
  int NumObjects(const Problem& at) const { return static_cast<int>(objects.size() + at.obstacles.size()); }
  const ClearanceObject& Object(const Problem& at, int o) const {
    const int ns = static_cast<int>(objects.size());
    return o < ns ? objects[o] : at.obstacles[o - ns];
  }
  bool Checked(int sphere, int o) const { return o >= static_cast<int>(objects.size()) || checked[sphere][o]; }

  // --- problem.cc -----------------------------------------------------------
  /// Throws std::invalid_argument "Plan: ..." for bad requests.
  void ValidateRequest(const PlanningRequest& req, int num_optimizers, int num_threads) const;
  /// The first attempt's problem (horizon, stretching, initial trajectory).
  Problem MakeProblem(const PlanningRequest& req, const Eigen::VectorXd& q_goal) const;
  /// Per attempt: free count, smoothness metric, steps, (initial smoothing),
  /// fixed bounds.
  void PrepareAttempt(Problem* at, bool smooth_base) const;
  void BuildSmoothness(Problem* at) const;
  void SetSteps(Problem* at) const;
  void PrepareWorkspace(const Problem& at, Workspace* ws) const;
  // Exact bounds (default TrajectoryBoundParams) of the waypoints [from, to]
  // of Q into (*out)[from..to]; *out must have Q.cols() entries.
  void ExactBounds(const Problem& at, const Eigen::MatrixXd& Q, int from, int to, std::vector<double>* out) const;
  // Bounds of the frozen prefix and the goal of at->base.
  void FixBounds(Problem* at) const;
  // Smallest surface distance (m) between the robot's spheres and the
  // predicted human spheres' means (actions with probability >=
  // kSeparationMinProbability) over the waypoints [from, to].
  double HumanSeparation(const Problem& at, const Eigen::MatrixXd& Q, int from, int to) const;

  // --- cost_terms.cc, dynamic_cost.cc: each adds its value to *ev and, if
  // G != nullptr, its gradient to the free columns of *G. -------------------
  void Evaluate(const Problem& at, const Eigen::MatrixXd& Q, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const;
  void AddSmoothnessCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const;
  void AddGoalCost(const Problem& at, const Eigen::MatrixXd& Q, CostTerms* ev, Eigen::MatrixXd* G) const;
  void AddLimitCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const;
  void AddObstacleCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const;
  void AddDynamicCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const;
  void AddSeparationCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const;
  void AddPersonSeparationCost(const Problem::Person& person, const Problem& at, Workspace* ws, CostTerms* ev,
                               Eigen::MatrixXd* G) const;
  // --- ssm_cost.cc: the separation monitor's rule along a plan -------------
  // Last waypoint the rule judges (ssm_horizon), -1 when off or nobody.
  int SsmLastWaypoint(const Problem& at) const;
  // Called per sphere pair near enough to matter (margin < ssm_activation):
  // where it is, delta (robot - human centre, m) and the pair rule's
  // result; returns false to stop.
  using SsmPairVisitor = std::function<bool(const SsmVisit& at, const Eigen::Vector3d& delta, const safety::SsmPair& pair)>;
  // Waypoints [from, to] with the FK in data[from .. min(to + 1, n)].
  // The factor on the plan's robot speed in the ssm pair rule: the
  // monitor's min_speed_scale with ssm_predicts_slowing (and its speed
  // reduction on), else 1.
  double SsmRuleSpeedScale() const;
  void VisitSsmPairs(const Problem& at, const std::vector<collision::RobotData>& data, int from, int to,
                     const SsmPairVisitor& visit) const;
  void AddSsmCost(const Problem& at, Workspace* ws, CostTerms* ev, Eigen::MatrixXd* G) const;
  // The rule over the waypoints [from, min(to, SsmLastWaypoint)] of Q.
  // FK and bookkeeping in ws (its data are overwritten).
  SsmJudgement JudgeSsm(const Problem& at, const Eigen::MatrixXd& Q, int from, int to, Workspace* ws) const;
  // The dynamic term's parts: waypoints whose bound may exceed its
  // activation, their bounds, and the gradient at one waypoint.
  // Each for one person `p`; the person's bounds of the free waypoints into *out.
  void FindActiveWaypoints(const Problem& at, int p, double log_negligible, Workspace* ws) const;
  void EvaluateActiveBounds(const Problem& at, int p, const collision::TrajectoryBoundParams& bp, Workspace* ws,
                            std::vector<collision::WaypointBound>* out) const;
  void AddBoundGradient(const Problem& at, int p, int i, const collision::WaypointBound& wb, double scale,
                        Workspace* ws, Eigen::MatrixXd* G) const;
  // The union over persons of ws->person_bounds into *out (the largest
  // share's pair and action, exact only when every share is).
  void CombineBounds(const Problem& at, Workspace* ws, std::vector<collision::WaypointBound>* out) const;

  // --- itomp_optimizer.cc ----------------------------------------------------
  void Project(const Problem& at, Eigen::MatrixXd* Q) const;
  // Static check (limits, clearance at substeps) and bound check.
  void Check(const Problem& at, const CostTerms& ev, Workspace* ws, Candidate* c) const;
  void StartOptimizer(const Problem& at, int o, std::uint64_t seed, Workspace* ws, OptimizerState* st) const;
  void IterateOptimizer(const Problem& at, int until, Workspace* ws, OptimizerState* st) const;
  void CheckOptimizer(const Problem& at, Workspace* ws, OptimizerState* st, Clock::time_point t0) const;

  // --- multi_start.cc --------------------------------------------------------
  std::vector<Candidate> RunOptimizers(const Problem& at, int num_opt, int num_threads, std::uint64_t seed,
                                       Clock::time_point t0) const;
  static Selection Select(const std::vector<Candidate>& cands);

  // --- wait_insertion.cc -----------------------------------------------------
  /// Inserts a wait into *at: holds the last safe pose of `ref` (or the end
  /// of the frozen prefix when ref is null) for wait_steps waypoints.
  void InsertWait(Problem* at, const Candidate* ref, int wait_steps) const;
};

}  // namespace iplan::planning::internal

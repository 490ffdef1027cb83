// Batched collision bound of a robot trajectory against a human prediction
// (METHOD.md section 4, eq. 4.7 with the mixture over actions):
//
//   P_i = max over (robot sphere k, human sphere l) of
//         sum_c p(c) * PairBound(B_k(q_i), C_l^c(t_i)).
//
// Split as in Pinocchio's Model/Data: HumanPrediction and
// RobotSpheresTrajectory are inputs sized once (they allocate on
// construction), TrajectoryBoundWorkspace is preallocated scratch space, and
// EvaluateTrajectoryBound does not allocate.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "iplan/collision/bound.h"

namespace iplan::collision {

/// The predicted person: for each action c its probability p(c), and for each
/// action, time step and human sphere the Gaussian of the sphere's centre
/// (world frame W, m, m^2). Sphere radii and segment ids are per sphere and
/// shared by all actions and steps.
/// Not thread-safe for writing; const methods are thread-safe.
class HumanPrediction {
 public:
  /// Per (step, sphere) summary over actions, used to prune pairs.
  struct Summary {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< centre of the means' bounding ball (m)
    double spread = 0.0;         ///< radius of that ball (m): max_c ||mu_c - centre||
    double max_log_peak = 0.0;   ///< max_c log of the density's peak value
    double max_eigenvalue = 0.0; ///< max_c largest covariance eigenvalue (m^2)
    double half_inverse_max_eigenvalue = 0.0;  ///< 0.5 / max_eigenvalue (1/m^2)
  };

  /// Allocates storage for num_actions x num_steps x radii.size() Gaussians,
  /// all initialised to N(0, I) with probability 1/num_actions each.
  /// @param radii    human sphere radii (m), each >= 0.
  /// @param segments segment id per sphere (same size as radii), reported in
  ///                 results; pass an empty vector for "sphere index".
  /// @throws std::invalid_argument on non-positive counts, negative radii or
  ///         size mismatch (message names the values).
  HumanPrediction(int num_actions, int num_steps, std::vector<double> radii,
                  std::vector<int> segments = {});

  int num_actions() const { return num_actions_; }
  int num_steps() const { return num_steps_; }
  int num_spheres() const { return static_cast<int>(radii_.size()); }
  double radius(int sphere) const { return radii_[sphere]; }
  int segment(int sphere) const { return segments_[sphere]; }
  /// m/s the separation monitor adds to this sphere's speed towards the
  /// robot beyond its predicted mean motion (0 by default; a depth point not
  /// tracked: the ISO default speed; a tracked part: its velocity's
  /// uncertainty). Used where the planner predicts the monitor, not by the
  /// bound: the sphere keeps its own radius.
  double speed_allowance(int sphere) const { return speed_allowances_[sphere]; }
  /// Sets speed_allowance(sphere); false (unchanged) unless finite and >= 0.
  bool set_speed_allowance(int sphere, double v);
  double action_probability(int action) const { return probabilities_[action]; }

  /// Sets p(action) (>= 0; the probabilities should sum to at most 1, the
  /// bound is for the mixture as given). Does not allocate.
  void set_action_probability(int action, double p) {
    probabilities_[action] = p;
    summaries_up_to_date_ = false;
  }

  /// Factorises and stores the Gaussian of a sphere's centre. Does not
  /// allocate. @returns false if `cov` is not finite and positive definite
  /// (the stored value is then unchanged).
  bool SetSphere(int action, int step, int sphere, const Eigen::Vector3d& mean,
                 const Eigen::Matrix3d& cov);

  const FactorizedGaussian& sphere(int action, int step, int sphere) const {
    return gaussians_[Index(action, step, sphere)];
  }

  /// Recomputes the per (step, sphere) pruning summaries. Must be called after
  /// the last SetSphere / set_action_probability and before evaluation.
  /// Does not allocate.
  void UpdateSummaries();

  const Summary& summary(int step, int sphere) const {
    return summaries_[step * num_spheres() + sphere];
  }
  /// Sum of the action probabilities (valid after UpdateSummaries).
  double probability_sum() const { return probability_sum_; }
  /// False after any SetSphere / set_action_probability until
  /// UpdateSummaries; EvaluateTrajectoryBound refuses stale summaries (the
  /// pruning would not be sound).
  bool summaries_up_to_date() const { return summaries_up_to_date_; }

 private:
  int Index(int action, int step, int sphere) const {
    return (action * num_steps_ + step) * num_spheres() + sphere;
  }
  int num_actions_;
  int num_steps_;
  std::vector<double> radii_;
  std::vector<int> segments_;
  std::vector<double> speed_allowances_;
  std::vector<double> probabilities_;
  std::vector<FactorizedGaussian> gaussians_;
  std::vector<Summary> summaries_;
  double probability_sum_ = 1.0;
  bool summaries_up_to_date_ = false;
};

/// Robot sphere centres along a trajectory (world frame W, m).
struct RobotSpheresTrajectory {
  /// Radius of each robot sphere (m), size S.
  std::vector<double> radii;
  /// Link index of each robot sphere (reported in results), size S.
  std::vector<int> links;
  /// Centres, 3 x (num_waypoints * S): column w * S + k is sphere k at
  /// waypoint w.
  Eigen::Matrix3Xd centres;
  /// Prediction time step of each waypoint, size num_waypoints.
  std::vector<int> steps;

  int num_spheres() const { return static_cast<int>(radii.size()); }
  int num_waypoints() const { return static_cast<int>(steps.size()); }
};

/// Tuning of the batched evaluation; the result is sound for any values.
struct TrajectoryBoundParams {
  /// Pairs whose upper bound is at most this are not evaluated exactly. If the
  /// waypoint's exact maximum is below it, the reported bound is the largest
  /// such upper bound instead (still an upper bound, flagged not exact).
  double negligible = 1e-12;
  /// Check validity; returns an empty string when valid, else the reason.
  std::string Validate() const;
};

/// Bound at one waypoint and the pair that attains it.
struct WaypointBound {
  /// Upper bound on the probability of contact at this waypoint, in [0, 1].
  double bound = 0.0;
  /// True when `bound` is the exact maximum of the pair mixtures; false when
  /// every pair was below TrajectoryBoundParams::negligible and `bound` is an
  /// upper bound of them.
  bool exact = true;
  int robot_sphere = -1;   ///< argmax robot sphere, -1 if none evaluated
  int robot_link = -1;     ///< its link
  int human_sphere = -1;   ///< argmax human sphere
  int human_segment = -1;  ///< its segment
  int action = -1;         ///< action with the largest term p(c) * bound_c
  /// Pairs evaluated exactly / skipped by the pruning tests (diagnostics).
  int pairs_evaluated = 0;
  int pairs_pruned = 0;
};

/// Preallocated scratch space for EvaluateTrajectoryBound.
struct TrajectoryBoundWorkspace {
  /// Allocates for up to `max_robot_spheres` x `max_human_spheres` pairs.
  TrajectoryBoundWorkspace(int max_robot_spheres, int max_human_spheres);
  std::vector<double> log_upper;   ///< per pair, level-1 log upper bound
  std::vector<double> log_volume;  ///< per pair, log V(r_robot + r_human)
};

/// Evaluates P_i for every waypoint of `trajectory` against `prediction`.
/// @param prediction  with summaries up to date (UpdateSummaries).
/// @param trajectory  steps[w] must be in [0, prediction.num_steps()).
/// @param workspace   sized for trajectory.num_spheres() x
///                    prediction.num_spheres() pairs; must not be null.
/// @param out         must already have size trajectory.num_waypoints()
///                    (resized if not, which allocates once).
/// Aborts (our bug / caller contract) on size mismatch, bad step index or
/// stale prediction summaries.
/// Thread-safe for distinct workspaces/outputs; does not allocate when `out`
/// has the right size.
void EvaluateTrajectoryBound(const HumanPrediction& prediction,
                             const RobotSpheresTrajectory& trajectory,
                             const TrajectoryBoundParams& params,
                             TrajectoryBoundWorkspace* workspace,
                             std::vector<WaypointBound>* out);

/// Mixture bound of one pair: sum_c p(c) * PairBound (each clamped to 1),
/// robot sphere at `b` (m, W) with radius `r_robot` (m) against human sphere
/// `sphere` at `step`. Writes the action with the largest term to
/// `argmax_action` if not null. Thread-safe; does not allocate.
double EvaluateMixtureBound(const HumanPrediction& prediction, int step, int sphere,
                            const Eigen::Vector3d& b, double r_robot,
                            int* argmax_action = nullptr);

}  // namespace iplan::collision

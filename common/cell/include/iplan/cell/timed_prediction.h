// The predicted person in time: the sphere-level Gaussian mixture the
// collision bound works on (collision::HumanPrediction), with the time of
// every step. The one step-time convention of the cell (what the intent
// service publishes, docs/intent.md):
//
//   step k (0-based) is at  t_k = t0 + (k + 1) time_step,
//
// t0 the stamp of the observation the prediction starts from. Step 0 is one
// step after the observation, never the observation itself.
//
// The planner takes the same timing relative to its first waypoint
// (PlanningRequest::prediction_start, "time of step 0 minus the time of
// waypoint 0"): StartRelativeTo() gives it. Not thread-safe.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "iplan/collision/human_model.h"
#include "iplan/collision/joint_mixture.h"
#include "iplan/collision/trajectory_bound.h"
#include "iplan/cell/people.h"

namespace iplan::cell {

class TimedPrediction {
 public:
  /// Empty (one action, one step, no observation); Build fills it.
  TimedPrediction() : spheres_(1, 1, {0.1}) {}
  /// Builds the sphere prediction of `body` from a joint-level mixture.
  /// Returns why it is refused (see collision::BuildSpherePrediction; a
  /// time_step that is not > 0); *out is then unchanged. Allocates.
  static std::optional<std::string> Build(const collision::HumanBodyModel& body,
                                          const collision::JointMixture& in, TimedPrediction* out);

  int64_t t0_ns() const { return t0_ns_; }          ///< observation time (ns since the epoch)
  double time_step() const { return time_step_; }   ///< s between steps
  int num_steps() const { return spheres_.num_steps(); }
  /// Absolute time of step k (ns), t0 + (k + 1) time_step.
  int64_t StepTime(int k) const { return t0_ns_ + static_cast<int64_t>((k + 1) * time_step_ * 1e9); }
  /// Time of step 0 minus `origin_ns`, in s (the planner's prediction_start).
  double StartRelativeTo(int64_t origin_ns) const { return (t0_ns_ - origin_ns) * 1e-9 + time_step_; }
  /// True when the observation is at most `max_age_ns` old at now_ns.
  bool FreshAt(int64_t now_ns, int64_t max_age_ns) const { return now_ns - t0_ns_ <= max_age_ns; }

  /// Sphere Gaussians per action and step, summaries up to date.
  const collision::HumanPrediction& spheres() const { return spheres_; }
  /// Names of the actions, in the mixture's order.
  const std::vector<std::string>& actions() const { return actions_; }

 private:
  int64_t t0_ns_ = 0;
  double time_step_ = 0;
  std::vector<std::string> actions_;
  collision::HumanPrediction spheres_;
};

/// What the collision-risk monitor and the replanner both do with a
/// received prediction: drop the people whose newest prediction is older
/// than `stale_after_s` (s) at its observation time, build it for `body`, and
/// keep it as `body_id`'s newest in `store`. Returns why it was refused (the
/// build's reason, or "prediction: " and the store's: out of order, too many
/// people); the store then keeps what it had, less the expired. Allocates.
std::optional<std::string> KeepNewestPrediction(const collision::HumanBodyModel& body, BodyId body_id,
                                                const collision::JointMixture& in, double stale_after_s,
                                                PerBody<TimedPrediction>* store);

}  // namespace iplan::cell

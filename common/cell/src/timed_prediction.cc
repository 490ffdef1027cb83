#include "iplan/cell/timed_prediction.h"

#include <cmath>

namespace iplan::cell {

std::optional<std::string> TimedPrediction::Build(const collision::HumanBodyModel& body,
                                                  const collision::JointMixture& in, TimedPrediction* out) {
  if (!(in.time_step > 0) || !std::isfinite(in.time_step)) return std::string("time_step must be > 0");
  TimedPrediction p;
  if (auto why = collision::BuildSpherePrediction(body, in, &p.spheres_)) return why;
  p.t0_ns_ = in.t0_ns;
  p.time_step_ = in.time_step;
  p.actions_ = in.actions;
  *out = std::move(p);
  return std::nullopt;
}

std::optional<std::string> KeepNewestPrediction(const collision::HumanBodyModel& body, BodyId body_id,
                                                const collision::JointMixture& in, double stale_after_s,
                                                PerBody<TimedPrediction>* store) {
  TimedPrediction p;
  if (auto why = TimedPrediction::Build(body, in, &p)) return why;
  store->Expire(in.t0_ns, static_cast<int64_t>(stale_after_s * 1e9));
  if (auto why = store->Update(body_id, p.t0_ns(), std::move(p))) return "prediction: " + *why;
  return std::nullopt;
}

}  // namespace iplan::cell

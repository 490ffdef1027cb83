#include "stop_audit.h"

#include <algorithm>
#include <utility>

#include "fixed_text.h"
#include "iplan/core/stats.h"

namespace iplan::cli {

double AuditedStop::After() const {
  if (end_s < start_s) return 0;  // still going on
  return std::max(0.0, end_s - std::max(start_s, last_inside_s));
}

void StopAudit::Advance(double t_s) {
  if (!(t_s > accounted_to_)) return;
  if (inside_ && open_) {
    open_->true_inside_s += t_s - std::max(accounted_to_, open_->start_s);
    open_->last_inside_s = t_s;
  } else if (inside_) {
    unstopped_inside_s_ += t_s - accounted_to_;
    stretch_s_ += t_s - accounted_to_;
    longest_unstopped_inside_s_ = std::max(longest_unstopped_inside_s_, stretch_s_);
  }
  accounted_to_ = t_s;
}

void StopAudit::StopStarted(double t_s, std::string reason) {
  if (open_) StopEnded(t_s);  // two starts without an end: the first ends here
  Advance(t_s);
  stretch_s_ = 0;
  open_ = AuditedStop{};
  open_->start_s = t_s;
  open_->reason = std::move(reason);
  // The person within S_p as the stop starts: the stretch reaches into it.
  if (inside_) open_->last_inside_s = t_s;
}

void StopAudit::StopEnded(double t_s) {
  if (!open_) return;
  Advance(t_s);
  open_->end_s = std::max(t_s, open_->start_s);
  ended_.push_back(std::move(*open_));
  open_.reset();
}

void StopAudit::Judge(double t_s, bool inside) {
  if (t_s < judged_at_) return;
  Advance(t_s);
  if (!inside) stretch_s_ = 0;
  inside_ = inside;
  judged_at_ = t_s;
  ++judgements_;
  if (open_ && inside) open_->last_inside_s = std::max(open_->last_inside_s, t_s);
}

StopAuditSummary Summarize(const StopAudit& audit, double since_s, double allowance_s) {
  StopAuditSummary s;
  s.allowance_s = allowance_s;
  std::vector<double> outlast;
  for (const AuditedStop& stop : audit.stops()) {
    if (stop.start_s < since_s) continue;
    ++s.stops;
    if (stop.true_inside_s > 0) ++s.with_person_within;  // as Describe(stop) says it
    if (stop.Outlast() > allowance_s) ++s.outlasting;
    outlast.push_back(stop.Outlast());
    s.after_max_s = std::max(s.after_max_s, stop.After());
  }
  const core::Summary o = core::Summarize(std::move(outlast));  // zeros when empty
  s.outlast_p50_s = o.p50;
  s.outlast_max_s = o.max;
  s.unstopped_inside_s = audit.unstopped_inside_s();
  s.longest_unstopped_inside_s = audit.longest_unstopped_inside_s();
  return s;
}

std::string Describe(const AuditedStop& stop) {
  return "at " + Fixed(stop.start_s, 1) + " s for " + Fixed(stop.Duration(), 2) + " s (" +
         (stop.true_inside_s > 0 ? "person within S_p " + Fixed(stop.true_inside_s, 2) + " s, " + Fixed(stop.After(), 2) +
                                       " s after they left"
                                 : std::string("person never within S_p")) +
         ")";
}

std::string Describe(const StopAuditSummary& s) {
  return std::to_string(s.stops) + " after the safe start, " + std::to_string(s.with_person_within) +
         " with the person within S_p; a stop outlasts their stay there by median " + Fixed(s.outlast_p50_s, 2) +
         " s, max " + Fixed(s.outlast_max_s, 2) + " s (after they left: max " + Fixed(s.after_max_s, 2) + " s); " +
         std::to_string(s.outlasting) + " by more than the resume delay (" + Fixed(s.allowance_s, 2) +
         " s); the person within S_p with no stop in force " + Fixed(s.unstopped_inside_s, 2) + " s in all, at most " +
         Fixed(s.longest_unstopped_inside_s, 2) + " s at a time";
}

namespace {

// The monitor's parameters, judging the truth: the human speed always
// measured, never degraded to the default speed for want of a forecast,
// and a person always there.
collision_risk::RiskParams TruthParams(collision_risk::RiskParams p) {
  p.ssm.measure_human_speed = true;
  p.ssm.degrade_without_prediction = false;
  p.person_required = false;
  return p;
}

}  // namespace

TrueSeparationJudge::TrueSeparationJudge(collision::RobotModel robot, collision::HumanBodyParams body,
                                         collision_risk::RiskParams params)
    : monitor_(std::move(robot), std::move(body), TruthParams(std::move(params))) {}

std::optional<std::string> TrueSeparationJudge::UpdateRobotState(int64_t stamp_ns, const std::vector<std::string>& names,
                                                                 const std::vector<double>& positions) {
  auto why = monitor_.UpdateRobotState(stamp_ns, names, positions);
  has_state_ = has_state_ || !why;
  return why;
}

std::optional<std::string> TrueSeparationJudge::UpdateTrajectory(int64_t start_ns, const std::vector<std::string>& names,
                                                                 const std::vector<double>& times,
                                                                 const std::vector<std::vector<double>>& positions) {
  return monitor_.UpdateTrajectory(start_ns, names, times, positions);
}

std::optional<std::string> TrueSeparationJudge::UpdateTruth(int64_t stamp_ns, const std::vector<std::string>& names,
                                                            const std::vector<Eigen::Vector3d>& positions) {
  auto why = monitor_.UpdateSkeleton(stamp_ns, names, positions);
  if (!why) {
    truth_stamps_.push_back(stamp_ns);
    const auto window = static_cast<int64_t>(monitor_.params().ssm.speed_window * 1e9);
    while (truth_stamps_.size() > 2 && stamp_ns - truth_stamps_[1] >= window) truth_stamps_.pop_front();
  }
  return why;
}

std::optional<bool> TrueSeparationJudge::Inside(int64_t now_ns) {
  // The monitor measures the speed over a truth at least half its window
  // old; before that it would take the default speed, which is no truth.
  const auto window = static_cast<int64_t>(monitor_.params().ssm.speed_window * 1e9);
  const bool measured =
      truth_stamps_.size() >= 2 && std::any_of(truth_stamps_.begin(), truth_stamps_.end(), [&](int64_t t) {
        const int64_t dt = truth_stamps_.back() - t;
        return dt <= window && dt >= window / 2;
      });
  if (!has_state_ || !measured) return std::nullopt;
  last_ = monitor_.Evaluate(now_ns);
  // No fresh truth or robot state: nothing to judge (Evaluate then reports
  // nobody seen).
  if (last_.num_people == 0) return std::nullopt;
  return last_.verdict == collision_risk::Verdict::kProtectiveStop;
}

}  // namespace iplan::cli

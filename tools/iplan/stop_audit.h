// Protective stops judged against the true person, for `iplan demo`.
//
// In the simulated cell the person's true body is known
// (/iplan/sim/human_truth); the cell's monitors see only their sensors. A
// stop is needed while the true person stands within the protective
// separation distance S_p of the robot's motion (ISO/TS 15066); a stop that
// goes on after that costs time for nothing.
//
// TrueSeparationJudge applies the collision-risk monitor's own separation
// rule (collision_risk::RiskMonitor: directed S_p per sphere pair, retreat,
// speed reduction) to the true body at its true speed, with the robot's
// state and executing trajectory: "within S_p" is the monitor's
// PROTECTIVE_STOP verdict on the truth, i.e. a pair that even the slowest
// allowed speed leaves inside S_p. The prediction layer (the collision
// bound) is not judged: the truth has no forecast.
//
// StopAudit times each stop against those judgements: how long the true
// person was within S_p during the stop, how much longer the stop lasted
// (issue 29: "no stop that lasts longer than the person stays within the
// protective separation"), and how much of that came after they left.
//
// Units: s (audit times, relative to the demo's start), m, m/s; stamps in
// ns since the epoch. Frames: world. No DDS types; not thread-safe.
#pragma once

#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "services/collision_risk/core/risk_monitor.h"

namespace iplan::cli {

/// One protective stop as the audit saw it.
struct AuditedStop {
  double start_s = 0;
  double end_s = -1;  ///< -1 while the stop goes on
  std::string reason;
  double true_inside_s = 0;  ///< s of the stop with the true person within S_p
  /// End of the last stretch within S_p that overlaps the stop (s), or
  /// -infinity when the true person was never within S_p during it.
  double last_inside_s = -std::numeric_limits<double>::infinity();
  double Duration() const { return end_s - start_s; }
  /// s the stop lasted longer than the true person stayed within S_p
  /// during it: Duration() - true_inside_s (the criterion).
  double Outlast() const { return Duration() - true_inside_s; }
  /// s of that after the person last stood within S_p (the whole stop when
  /// they never did during it; 0 when they still were as it ended); the
  /// rest of Outlast() came before they were within S_p.
  double After() const;
};

/// The stops' timeline against piecewise-constant truth judgements.
class StopAudit {
 public:
  void StopStarted(double t_s, std::string reason);
  void StopEnded(double t_s);
  /// The true person is (inside = true) or is not within S_p from t_s until
  /// the next judgement. Judgements come in time order; an older one is
  /// ignored.
  void Judge(double t_s, bool inside);
  /// Ended stops, in order.
  const std::vector<AuditedStop>& stops() const { return ended_; }
  /// Number of judgements taken (0: the truth never came, nothing audited).
  int judgements() const { return judgements_; }
  /// s, so far, with the true person within S_p and no stop in force (the
  /// robot free to move, perhaps slowed, where the monitor's rule on the
  /// truth would have stopped it), in total and the longest stretch.
  double unstopped_inside_s() const { return unstopped_inside_s_; }
  double longest_unstopped_inside_s() const { return longest_unstopped_inside_s_; }

 private:
  void Advance(double t_s);  // the current judgement holds until t_s

  std::vector<AuditedStop> ended_;
  std::optional<AuditedStop> open_;
  bool inside_ = false;
  double judged_at_ = -std::numeric_limits<double>::infinity();
  double accounted_to_ = -std::numeric_limits<double>::infinity();  // time is accounted for up to here
  double unstopped_inside_s_ = 0, longest_unstopped_inside_s_ = 0;
  double stretch_s_ = 0;  // the current stretch within S_p without a stop
  int judgements_ = 0;
};

/// A summary of the stops that started at or after `since_s` (the demo's
/// first task: the stop before it is the cell's safe start).
struct StopAuditSummary {
  int stops = 0;                 ///< ended stops audited
  int with_person_within = 0;    ///< ... with the true person within S_p at some time during the stop
  /// ... that outlast the person's stay by more than `allowance_s`: the
  /// supervisor's resume delay, how long a stop's every cause must stay
  /// clear before the robot resumes (a stop outlasts the stay by that much
  /// by design).
  int outlasting = 0;
  double allowance_s = 0;
  /// Outlast() and After() over the audited stops (nearest rank; 0 when none).
  double outlast_p50_s = 0, outlast_max_s = 0, after_max_s = 0;
  /// StopAudit::unstopped_inside_s() and its longest stretch (whole run).
  double unstopped_inside_s = 0, longest_unstopped_inside_s = 0;
};
StopAuditSummary Summarize(const StopAudit& audit, double since_s, double allowance_s);

/// One line for the demo's summary: "at 7.7 s for 0.60 s (person within S_p
/// 0.10 s, 0.20 s after they left)".
std::string Describe(const AuditedStop& stop);
/// "4 after the safe start, 4 with the person within S_p; ...".
std::string Describe(const StopAuditSummary& summary);

/// The monitor's separation rule on the true body.
class TrueSeparationJudge {
 public:
  /// `params`: the cell's collision-risk parameters (its ISO/TS 15066
  /// section); the human speed is always measured from the truth, over the
  /// monitor's own speed_window, never the default speed. Throws
  /// std::invalid_argument on invalid parameters.
  TrueSeparationJudge(collision::RobotModel robot, collision::HumanBodyParams body, collision_risk::RiskParams params);

  /// Inputs, as the collision-risk monitor takes them; each returns why it
  /// was refused, or nullopt.
  std::optional<std::string> UpdateRobotState(int64_t stamp_ns, const std::vector<std::string>& names,
                                              const std::vector<double>& positions);
  std::optional<std::string> UpdateTrajectory(int64_t start_ns, const std::vector<std::string>& names,
                                              const std::vector<double>& times,
                                              const std::vector<std::vector<double>>& positions);
  std::optional<std::string> UpdateTruth(int64_t stamp_ns, const std::vector<std::string>& names,
                                         const std::vector<Eigen::Vector3d>& positions);

  /// Whether the true person is within S_p at now_ns: nullopt until the
  /// robot state and the truth are known and fresh, and while the truth
  /// does not yet span half the speed window (no measured speed).
  std::optional<bool> Inside(int64_t now_ns);
  /// The last judgement's report (its reason names the binding pair).
  const collision_risk::RiskReport& last_report() const { return last_; }

 private:
  collision_risk::RiskMonitor monitor_;
  bool has_state_ = false;
  std::deque<int64_t> truth_stamps_;  // ns, within the speed window of the newest
  collision_risk::RiskReport last_;
};

}  // namespace iplan::cli

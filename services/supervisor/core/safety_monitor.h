// Deadline and liveliness monitor of the supervisor: every watched topic has
// a deadline (from the topic catalogue); a late or vanished publisher, or a
// PROTECTIVE_STOP verdict of the collision-risk service, means the robot
// must stop, naming the culprit; when every cause has cleared (data flows
// again, the verdict is no longer a stop) the cell resumes by itself.
// Topics never seen since start count as late (safe start). A topic with a
// deadline (SetDeadline) also counts as late when no *usable* sample came for
// longer than it: the caller reports only samples that passed every check,
// so a stream of rejected samples, which meets the DDS deadline, still stops
// the robot. No DDS types; times in ns since the epoch. Not thread-safe.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "iplan/cell/status.h"

namespace iplan::supervisor {

struct SafetyDecision {
  bool stop = true;
  std::string reason;  ///< every current cause, "; "-separated; "all inputs healthy" on resume
};

class SafetyMonitor {
 public:
  explicit SafetyMonitor(std::vector<std::string> watched_topics);

  /// A usable sample of `topic` arrived at `now_ns`.
  void OnData(const std::string& topic, int64_t now_ns = 0);
  /// Seconds without a usable sample after which `topic` counts as late
  /// (0: only the DDS deadline events count).
  void SetDeadline(const std::string& topic, double seconds);
  void OnDeadlineMissed(const std::string& topic);
  void OnLivelinessLost(const std::string& topic, int alive_writers);
  /// Collision risk's latest verdict; a protective stop is a cause. A
  /// `retreating` verdict (the robot moving out of the person's way) resumes
  /// at once when it clears the last cause: holding it for the resume delay
  /// would keep the robot where the person is coming.
  void OnRiskVerdict(cell::Verdict verdict, const std::string& reason, bool retreating = false);

  /// The decision at `now_ns`; `changed` is set when it differs from the
  /// last call. After a stop, the cell resumes only once every cause has been
  /// clear for the resume delay (no stop/resume chatter at a threshold),
  /// or at once for a retreat (OnRiskVerdict).
  SafetyDecision Evaluate(bool* changed, int64_t now_ns = 0);
  /// Seconds every cause must stay clear before resuming (default 0).
  void SetResumeDelay(double seconds) { resume_delay_ns_ = static_cast<int64_t>(seconds * 1e9); }
  /// Causes per topic ("late", "lost", "never seen").
  const std::map<std::string, std::string>& causes() const { return causes_; }

 private:
  std::vector<std::string> topics_;
  std::map<std::string, std::string> causes_;
  std::map<std::string, int64_t> deadline_ns_, last_data_ns_;
  std::string risk_cause_;
  bool risk_retreat_ = false;
  std::optional<SafetyDecision> last_;
  int64_t resume_delay_ns_ = 0;
  std::optional<int64_t> clear_since_ns_;
  int64_t stop_since_ns_ = 0;                    // start of the current (or last) stop
  int64_t quick_resume_ns_ = INT64_MIN / 2;      // last resume at once (a retreat)
};

}  // namespace iplan::supervisor

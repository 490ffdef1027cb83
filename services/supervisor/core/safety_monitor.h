// Deadline and liveliness monitor of the supervisor: every watched topic has
// a deadline (from the topic catalogue); a late or vanished publisher, or a
// PROTECTIVE_STOP verdict of the collision-risk service, means the robot
// must stop, naming the culprit; when every cause has cleared (data flows
// again, the verdict is no longer a stop) the cell resumes by itself.
// Topics never seen since start count as late (safe start). No DDS types;
// times in ns since the epoch. Not thread-safe.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace iplan::supervisor {

struct SafetyDecision {
  bool stop = true;
  std::string reason;  ///< every current cause, "; "-separated; "all inputs healthy" on resume
};

class SafetyMonitor {
 public:
  explicit SafetyMonitor(std::vector<std::string> watched_topics);

  void OnData(const std::string& topic);
  void OnDeadlineMissed(const std::string& topic);
  void OnLivelinessLost(const std::string& topic, int alive_writers);
  /// verdict: 0 OK, 1 SLOW_DOWN, 2 PROTECTIVE_STOP (CollisionRisk constants).
  void OnRiskVerdict(uint8_t verdict, const std::string& reason);

  /// The decision now; `changed` is set when it differs from the last call.
  SafetyDecision Evaluate(bool* changed);
  /// Causes per topic ("late", "lost", "never seen").
  const std::map<std::string, std::string>& causes() const { return causes_; }

 private:
  std::vector<std::string> topics_;
  std::map<std::string, std::string> causes_;
  std::string risk_cause_;
  std::optional<SafetyDecision> last_;
};

}  // namespace iplan::supervisor

// The robot side of the cell's safety chain, built the way ISO 13849 builds
// a "de-energise to trip" circuit: the robot may move only while it holds a
// fresh PERMIT from each of its configured monitors (the supervisor and,
// independently, collision risk). Every monitor re-publishes its permit
// every period with a short validity; whatever silences a monitor (a crash,
// a freeze, a cut cable, a lost network) lets its permit lapse, and the
// robot stops within one validity. Nothing a monitor says can extend this:
// a permit's validity is capped by the robot's own configuration.
//
//   PermitGate gate({.monitors = {"iplan-supervisor", "iplan-collision_risk"}});
//   gate.OnPermit("iplan-supervisor", true, 0.2, "all inputs healthy", stamp_ns, now_ns);
//   if (!gate.Evaluate(now_ns).permitted) robot.Stop();
//
// A permit's life: it is held from its reception until
//   min(reception, stamp + clock_tolerance) + min(validity, max_validity),
// so a delayed or replayed permit (an old stamp) lapses early, and one
// stamped ahead of this clock by more than clock_tolerance is refused (a
// forged clock cannot buy time). A permit older than the one held from the
// same monitor is refused (no replay, no reordering).
//
// Times are ns since the epoch on this host's wall clock (the clock the
// monitors' stamps are in; hosts synchronised with NTP/PTP). No DDS types.
// Not thread-safe (one owner).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "iplan/core/name_value.h"

namespace iplan::safety {

struct PermitGateParams {
  /// Names of the monitors whose permits are all required (the writers'
  /// participant names, e.g. "iplan-supervisor"). Must not be empty.
  std::vector<std::string> monitors;
  /// s; a permit's own validity is capped at this.
  double max_validity = 0.25;
  /// s; permits stamped further ahead of this clock are refused, and a stamp
  /// older than reception by more than this counts against the validity.
  double clock_tolerance = 0.05;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(monitors, "monitors whose permits are all required (participant names), not empty"));
    a->Visit(IPLAN_NVP(max_validity, "s; a permit's validity is capped at this, in (0, 10]"));
    a->Visit(IPLAN_NVP(clock_tolerance, "s; permits stamped further ahead are refused, in [0, 1]"));
  }
  /// Empty when valid, else the reason.
  std::string Validate() const;
};

struct PermitDecision {
  bool permitted = false;
  /// Why not (every missing, lapsed or refusing monitor, "; "-separated), or
  /// what the permission rests on.
  std::string reason;
};

class PermitGate {
 public:
  /// Throws std::invalid_argument when `params` are invalid.
  explicit PermitGate(PermitGateParams params);

  /// A permit (`permit` true) or a stop (false) from `monitor`, stamped
  /// `stamp_ns` by the monitor, valid `validity_s` s, received at `now_ns`.
  /// Returns why it was refused (not a configured monitor, stamped ahead,
  /// older than the one held, validity not positive), else nullopt. A refused
  /// permit changes nothing.
  std::optional<std::string> OnPermit(const std::string& monitor, bool permit, double validity_s,
                                      const std::string& reason, int64_t stamp_ns, int64_t now_ns);
  /// The decision at `now_ns`.
  PermitDecision Evaluate(int64_t now_ns) const;

  const PermitGateParams& params() const { return params_; }

 private:
  struct Held {
    bool permit = false;
    std::string reason;
    int64_t stamp_ns = 0;
    int64_t expires_ns = 0;
  };
  PermitGateParams params_;
  std::string permitted_reason_;  // "permitted by <monitors>", built once (Evaluate runs every control step)
  std::map<std::string, Held> held_;
};

}  // namespace iplan::safety

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
//   gate.OnPermit("iplan-supervisor", writer_id, true, 0.2, "all inputs healthy", stamp_ns, now_ns);
//   if (!gate.Evaluate(now_ns).permitted) robot.Stop();
//
// A permit's life: it is held from its reception until
//   min(reception, stamp + clock_tolerance) + min(validity, max_validity),
// so a delayed or replayed permit (an old stamp) lapses early, and one
// stamped ahead of this clock by more than clock_tolerance is refused (a
// forged clock cannot buy time). A permit older than the one held from the
// same monitor is refused (no replay, no reordering).
//
// Stop wins. Each sample also carries the identity of the writer that sent
// it (`writer`: a stable key of the DDS writer, e.g. a hash of its GUID; the
// participant name is only what the writer claims to be). A STOP from any
// writer claiming monitor M is held for its own validity (capped like a
// permit's) and no PERMIT from another writer lifts it; only a newer PERMIT
// from the very writer that stopped ends it early (a monitor's own
// stop/resume cycle). Two distinct writers claiming one monitor within
// `writer_silence` of each other is a fault: Evaluate refuses, naming the
// monitor and both writers, until all but one of them have been silent for
// `writer_silence`. So a monitor that restarts (a new participant, hence a
// new writer) is accepted once its old writer has been silent that long;
// a restart faster than that is reported as two writers and clears by itself.
// A writer that claims a monitor while the real one has been silent for
// `writer_silence` is not detected (only DDS Security prevents that).
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
  /// s; two writers claiming one monitor are a fault until all but one have
  /// been silent this long; a new writer for a monitor (a restart) is
  /// accepted once the old one has been silent this long.
  double writer_silence = 2.0;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(monitors, "monitors whose permits are all required (participant names), not empty"));
    a->Visit(IPLAN_NVP(max_validity, "s; a permit's validity is capped at this, in (0, 10]"));
    a->Visit(IPLAN_NVP(clock_tolerance, "s; permits stamped further ahead are refused, in [0, 1]"));
    a->Visit(IPLAN_NVP(writer_silence, "s; two writers claiming one monitor stop the robot until all but one have been silent this long, in [0.1, 60]"));
  }
  /// Empty when valid, else the reason.
  std::string Validate() const;
};

struct PermitDecision {
  bool permitted = false;
  /// Why not (every missing, lapsed or refusing monitor, "; "-separated), or
  /// what the permission rests on.
  std::string reason;
  /// While permitted: the fraction of its trajectory's speed the robot may
  /// run at, 1 minus the largest speed_reduction of the permits held (ISO/TS
  /// 15066 speed reduction); 1 when no monitor asks to slow down.
  double speed_scale = 1.0;
};

/// Two writers claiming one monitor: raised when the second one is heard,
/// cleared when all but one have been silent for writer_silence.
struct WriterConflictEvent {
  bool raised = true;  ///< false: cleared
  std::string monitor;
  uint64_t first_writer = 0;   ///< the writer heard first (raised only)
  uint64_t second_writer = 0;  ///< the writer that joined it (raised only)
  std::string description;     ///< e.g. "2 writers claim iplan-supervisor: writer 00..01, writer 00..02"
};

/// "writer " + 16 hex digits: how the gate names a writer identity.
std::string WriterLabel(uint64_t writer);

class PermitGate {
 public:
  /// Throws std::invalid_argument when `params` are invalid.
  explicit PermitGate(PermitGateParams params);

  /// A permit (`permit` true) or a stop (false) claiming to be from
  /// `monitor`, sent by writer `writer` (a stable key of the sending writer),
  /// stamped `stamp_ns` by the monitor, valid `validity_s` s, received at
  /// `now_ns`. Returns why it was refused (not a configured monitor, stamped
  /// ahead, older than the one held from that writer, validity not
  /// positive), else nullopt. A refused sample changes nothing except that
  /// its writer counts as claiming `monitor` (a configured one). A stop is
  /// never refused for being older: it can only stop, and lapses by its stamp.
  /// `speed_reduction` (a permit's, in [0, 1]; refused outside): by how
  /// much the robot must slow down while this permit holds.
  /// Allocates only when a writer or stop is new; keeps at most 16 writers
  /// and 16 stops per monitor.
  std::optional<std::string> OnPermit(const std::string& monitor, uint64_t writer, bool permit, double validity_s,
                                      const std::string& reason, int64_t stamp_ns, int64_t now_ns,
                                      double speed_reduction = 0.0);
  /// The decision at `now_ns`.
  PermitDecision Evaluate(int64_t now_ns) const;
  /// Writer conflicts that began or ended since the last call, judged at
  /// `now_ns`, each reported once (for the caller to log). Evaluate does not
  /// depend on this being called.
  std::vector<WriterConflictEvent> TakeConflictEvents(int64_t now_ns);

  const PermitGateParams& params() const { return params_; }

 private:
  struct Held {
    bool valid = false;  // a sample was accepted from this writer
    bool permit = false;
    std::string reason;
    double speed_reduction = 0.0;
    int64_t stamp_ns = 0;
    int64_t expires_ns = 0;
  };
  struct Writer {
    uint64_t id = 0;
    int64_t first_ns = 0, last_ns = 0;  // heard (any sample claiming the monitor)
    Held held;
  };
  struct Stop {
    uint64_t writer = 0;
    std::string reason;
    int64_t stamp_ns = 0;
    int64_t expires_ns = 0;
  };
  struct Monitor {
    std::vector<Writer> writers;  // heard within writer_silence (older ones pruned on the next sample)
    std::vector<Stop> stops;      // in force or lapsed (pruned on the next sample)
    bool conflict_reported = false;
  };
  // Writers of `m` heard within writer_silence before `now_ns`.
  std::vector<const Writer*> Active(const Monitor& m, int64_t now_ns) const;
  std::string ConflictText(const std::string& name, const std::vector<const Writer*>& active) const;
  PermitGateParams params_;
  std::string permitted_reason_;  // "permitted by <monitors>", built once (Evaluate runs every control step)
  std::map<std::string, Monitor> monitors_;
};

}  // namespace iplan::safety

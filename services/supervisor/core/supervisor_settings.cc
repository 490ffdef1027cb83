#include "services/supervisor/core/supervisor_settings.h"

namespace iplan::supervisor {
namespace {

std::string InRange(const char* key, double v, double lo, double hi) {
  if (v >= lo && v <= hi) return "";
  return std::string(key) + " must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
         std::to_string(v);
}

}  // namespace

std::string SupervisorSettings::Validate() const {
  if (mode != "learning" && mode != "deployment") return "mode must be learning or deployment, got '" + mode + "'";
  if (std::string why = learning.Validate(); !why.empty()) return why;
  if (std::string why = tracker.Validate(); !why.empty()) return why;
  if (watch.empty() && mode == "deployment") {
    return "watch must name at least one topic in deployment (an empty list switches the deadline monitor off)";
  }
  if (!(pause_between_tasks >= 0)) return "pause_between_tasks must be >= 0";
  if (std::string why = InRange("resume_delay", resume_delay, 0.0, 10.0); !why.empty()) return why;
  if (max_episodes < 0) return "max_episodes must be >= 0";
  if (std::string why = InRange("permit_period", permit_period, 0.005, 1.0); !why.empty()) return why;
  if (std::string why = InRange("permit_validity", permit_validity, 0.01, 10.0); !why.empty()) return why;
  if (permit_validity < 2 * permit_period) {
    return "permit_validity must be at least twice permit_period (one late permit must not stop the cell)";
  }
  return InRange("command_resend_period", command_resend_period, 0.1, 60.0);
}

}  // namespace iplan::supervisor

#include "iplan/safety/permit_gate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace iplan::safety {
namespace {

std::string Seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3f s", s);
  return buf;
}

int64_t Ns(double s) { return static_cast<int64_t>(std::llround(s * 1e9)); }

}  // namespace

std::string PermitGateParams::Validate() const {
  if (monitors.empty()) return "permits: no monitors configured (the robot would move unsupervised)";
  for (std::size_t i = 0; i < monitors.size(); ++i) {
    if (monitors[i].empty()) return "permits: empty monitor name";
    if (std::find(monitors.begin(), monitors.begin() + static_cast<std::ptrdiff_t>(i), monitors[i]) !=
        monitors.begin() + static_cast<std::ptrdiff_t>(i)) {
      return "permits: monitor '" + monitors[i] + "' listed twice";
    }
  }
  if (!(max_validity > 0 && max_validity <= 10)) return "permits: max_validity must be in (0, 10] s";
  if (!(clock_tolerance >= 0 && clock_tolerance <= 1)) return "permits: clock_tolerance must be in [0, 1] s";
  return "";
}

PermitGate::PermitGate(PermitGateParams params) : params_(std::move(params)) {
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
  permitted_reason_ = "permitted by";
  for (std::size_t i = 0; i < params_.monitors.size(); ++i) permitted_reason_ += (i ? ", " : " ") + params_.monitors[i];
}

std::optional<std::string> PermitGate::OnPermit(const std::string& monitor, bool permit, double validity_s,
                                                const std::string& reason, int64_t stamp_ns, int64_t now_ns) {
  if (std::find(params_.monitors.begin(), params_.monitors.end(), monitor) == params_.monitors.end()) {
    return "'" + monitor + "' is not a configured monitor";
  }
  if (!(validity_s > 0) || !std::isfinite(validity_s)) return "validity " + std::to_string(validity_s) + " s is not positive";
  const int64_t tolerance_ns = Ns(params_.clock_tolerance);
  if (stamp_ns - now_ns > tolerance_ns) {
    return "stamped " + Seconds((stamp_ns - now_ns) * 1e-9) + " ahead of this clock (tolerance " +
           Seconds(params_.clock_tolerance) + ")";
  }
  auto it = held_.find(monitor);
  if (it != held_.end() && stamp_ns < it->second.stamp_ns) {
    return "older than the permit held (by " + Seconds((it->second.stamp_ns - stamp_ns) * 1e-9) + ")";
  }
  Held h;
  h.permit = permit;
  h.reason = reason;
  h.stamp_ns = stamp_ns;
  h.expires_ns = std::min(now_ns, stamp_ns + tolerance_ns) + Ns(std::min(validity_s, params_.max_validity));
  held_[monitor] = std::move(h);
  return std::nullopt;
}

PermitDecision PermitGate::Evaluate(int64_t now_ns) const {
  PermitDecision d;
  std::string why;
  auto add = [&why](const std::string& s) { why += (why.empty() ? "" : "; ") + s; };
  for (const std::string& m : params_.monitors) {
    auto it = held_.find(m);
    if (it == held_.end()) {
      add("no permit from " + m + " yet");
    } else if (now_ns >= it->second.expires_ns) {
      add("permit from " + m + " lapsed " + Seconds((now_ns - it->second.expires_ns) * 1e-9) + " ago");
    } else if (!it->second.permit) {
      add(m + " stops: " + it->second.reason);
    }
  }
  d.permitted = why.empty();
  d.reason = d.permitted ? permitted_reason_ : why;
  return d;
}

}  // namespace iplan::safety

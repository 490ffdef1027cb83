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

template <class T, class Pred>
void EraseIf(std::vector<T>* v, Pred pred) {
  v->erase(std::remove_if(v->begin(), v->end(), pred), v->end());
}

constexpr std::size_t kMaxWritersPerMonitor = 16;
constexpr std::size_t kMaxStopsPerMonitor = 16;

}  // namespace

std::string WriterLabel(uint64_t writer) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), "writer %016llx", static_cast<unsigned long long>(writer));
  return buf;
}

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
  if (!(writer_silence >= 0.1 && writer_silence <= 60)) return "permits: writer_silence must be in [0.1, 60] s";
  return "";
}

PermitGate::PermitGate(PermitGateParams params) : params_(std::move(params)) {
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
  permitted_reason_ = "permitted by";
  for (std::size_t i = 0; i < params_.monitors.size(); ++i) permitted_reason_ += (i ? ", " : " ") + params_.monitors[i];
}

std::optional<std::string> PermitGate::OnPermit(const std::string& monitor, uint64_t writer, bool permit,
                                                double validity_s, const std::string& reason, int64_t stamp_ns,
                                                int64_t now_ns, double speed_reduction) {
  if (std::find(params_.monitors.begin(), params_.monitors.end(), monitor) == params_.monitors.end()) {
    return "'" + monitor + "' is not a configured monitor";
  }
  Monitor& m = monitors_[monitor];
  // The writer claims the monitor whatever the sample says: note it first.
  const int64_t silence_ns = Ns(params_.writer_silence);
  EraseIf(&m.writers, [&](const Writer& w) { return now_ns - w.last_ns >= silence_ns && w.id != writer; });
  auto w = std::find_if(m.writers.begin(), m.writers.end(), [&](const Writer& x) { return x.id == writer; });
  if (w == m.writers.end()) {
    if (m.writers.size() >= kMaxWritersPerMonitor) {  // a flood of identities: forget the stalest
      m.writers.erase(std::min_element(m.writers.begin(), m.writers.end(),
                                       [](const Writer& a, const Writer& b) { return a.last_ns < b.last_ns; }));
    }
    m.writers.push_back(Writer{writer, now_ns, now_ns, Held{}});
    w = m.writers.end() - 1;
  } else {
    w->last_ns = std::max(w->last_ns, now_ns);
  }
  if (!(validity_s > 0) || !std::isfinite(validity_s)) return "validity " + std::to_string(validity_s) + " s is not positive";
  if (!(speed_reduction >= 0 && speed_reduction <= 1)) {
    return "speed_reduction " + std::to_string(speed_reduction) + " is outside [0, 1]";
  }
  const int64_t tolerance_ns = Ns(params_.clock_tolerance);
  if (stamp_ns - now_ns > tolerance_ns) {
    return "stamped " + Seconds((stamp_ns - now_ns) * 1e-9) + " ahead of this clock (tolerance " +
           Seconds(params_.clock_tolerance) + ")";
  }
  const int64_t expires_ns = std::min(now_ns, stamp_ns + tolerance_ns) + Ns(std::min(validity_s, params_.max_validity));
  Held& held = w->held;
  if (!permit) {
    // Stop wins: held for its validity whoever sent it; only a newer permit
    // from this same writer ends it early.
    EraseIf(&m.stops, [&](const Stop& x) { return now_ns >= x.expires_ns; });
    if (m.stops.size() >= kMaxStopsPerMonitor) {  // keep the stops that last longest
      auto first = std::min_element(m.stops.begin(), m.stops.end(),
                                    [](const Stop& a, const Stop& b) { return a.expires_ns < b.expires_ns; });
      if (first->expires_ns < expires_ns) m.stops.erase(first);
    }
    if (m.stops.size() < kMaxStopsPerMonitor) m.stops.push_back(Stop{writer, reason, stamp_ns, expires_ns});
    if (!held.valid || stamp_ns >= held.stamp_ns) held = Held{true, false, reason, 0.0, stamp_ns, expires_ns};
    return std::nullopt;
  }
  if (held.valid && stamp_ns < held.stamp_ns) {
    return "older than the permit held (by " + Seconds((held.stamp_ns - stamp_ns) * 1e-9) + ")";
  }
  held = Held{true, true, reason, speed_reduction, stamp_ns, expires_ns};
  EraseIf(&m.stops, [&](const Stop& x) { return x.writer == writer && stamp_ns > x.stamp_ns; });
  return std::nullopt;
}

std::vector<const PermitGate::Writer*> PermitGate::Active(const Monitor& m, int64_t now_ns) const {
  const int64_t silence_ns = Ns(params_.writer_silence);
  std::vector<const Writer*> active;
  for (const Writer& w : m.writers) {
    if (now_ns - w.last_ns < silence_ns) active.push_back(&w);
  }
  std::sort(active.begin(), active.end(), [](const Writer* a, const Writer* b) { return a->first_ns < b->first_ns; });
  return active;
}

std::string PermitGate::ConflictText(const std::string& name, const std::vector<const Writer*>& active) const {
  std::string s = std::to_string(active.size()) + " writers claim " + name + " (";
  for (std::size_t i = 0; i < active.size(); ++i) s += (i ? ", " : "") + WriterLabel(active[i]->id);
  return s + "): stopped until all but one have been silent for " + Seconds(params_.writer_silence);
}

PermitDecision PermitGate::Evaluate(int64_t now_ns) const {
  PermitDecision d;
  std::string why;
  double reduction = 0.0;
  auto add = [&why](const std::string& s) { why += (why.empty() ? "" : "; ") + s; };
  for (const std::string& name : params_.monitors) {
    auto it = monitors_.find(name);
    if (it == monitors_.end()) {
      add("no permit from " + name + " yet");
      continue;
    }
    const Monitor& m = it->second;
    const std::vector<const Writer*> active = Active(m, now_ns);
    if (active.size() > 1) add(ConflictText(name, active));
    const auto stop = std::find_if(m.stops.begin(), m.stops.end(), [&](const Stop& x) { return now_ns < x.expires_ns; });
    if (stop != m.stops.end()) {
      add(name + " stops: " + stop->reason);
      continue;
    }
    if (active.size() > 1) continue;
    // The permit of the writer heard last (the only one heard lately, if any).
    const Writer* w = nullptr;
    for (const Writer& x : m.writers) {
      if (x.held.valid && (!w || x.last_ns > w->last_ns)) w = &x;
    }
    if (!w) {
      add("no permit from " + name + " yet");
    } else if (now_ns >= w->held.expires_ns) {
      add("permit from " + name + " lapsed " + Seconds((now_ns - w->held.expires_ns) * 1e-9) + " ago");
    } else if (!w->held.permit) {
      add(name + " stops: " + w->held.reason);
    } else {
      reduction = std::max(reduction, w->held.speed_reduction);
    }
  }
  d.permitted = why.empty();
  d.reason = d.permitted ? permitted_reason_ : why;
  if (d.permitted) d.speed_scale = 1.0 - reduction;
  return d;
}

std::vector<WriterConflictEvent> PermitGate::TakeConflictEvents(int64_t now_ns) {
  std::vector<WriterConflictEvent> events;
  for (auto& [name, m] : monitors_) {
    const std::vector<const Writer*> active = Active(m, now_ns);
    if (active.size() > 1 && !m.conflict_reported) {
      m.conflict_reported = true;
      events.push_back({true, name, active[0]->id, active[1]->id, ConflictText(name, active)});
    } else if (active.size() <= 1 && m.conflict_reported) {
      m.conflict_reported = false;
      events.push_back({false, name, 0, 0,
                        "one writer claims " + name + " again (the others silent for " +
                            Seconds(params_.writer_silence) + ")"});
    }
  }
  return events;
}

}  // namespace iplan::safety

#include "safety_monitor.h"

#include <algorithm>

namespace iplan::supervisor {

SafetyMonitor::SafetyMonitor(std::vector<std::string> watched_topics) : topics_(std::move(watched_topics)) {
  for (const auto& t : topics_) causes_[t] = "never seen";
}

void SafetyMonitor::OnData(const std::string& topic, int64_t now_ns) {
  if (!causes_.count(topic)) return;
  causes_[topic].clear();
  last_data_ns_[topic] = now_ns;
}

void SafetyMonitor::SetDeadline(const std::string& topic, double seconds) {
  deadline_ns_[topic] = static_cast<int64_t>(seconds * 1e9);
}

void SafetyMonitor::OnDeadlineMissed(const std::string& topic) {
  if (causes_.count(topic) && causes_[topic].empty()) causes_[topic] = "deadline missed";
}

void SafetyMonitor::OnLivelinessLost(const std::string& topic, int alive_writers) {
  if (causes_.count(topic) && alive_writers == 0) causes_[topic] = "publisher gone (liveliness lost)";
}

void SafetyMonitor::OnRiskVerdict(cell::Verdict verdict, const std::string& reason, bool retreating) {
  risk_cause_ = verdict == cell::Verdict::kProtectiveStop ? "collision risk: " + reason : "";
  risk_retreat_ = retreating && verdict != cell::Verdict::kProtectiveStop;
}

SafetyDecision SafetyMonitor::Evaluate(bool* changed, int64_t now_ns) {
  SafetyDecision d;
  std::string reason;
  for (const auto& t : topics_) {
    std::string& c = causes_[t];
    const auto dl = deadline_ns_.find(t);
    const auto last = last_data_ns_.find(t);
    if (c.empty() && dl != deadline_ns_.end() && dl->second > 0 && last != last_data_ns_.end() &&
        now_ns - last->second > dl->second) {
      c = "no usable sample for " + std::to_string((now_ns - last->second) / 1000000) + " ms (deadline " +
          std::to_string(dl->second / 1000000) + " ms)";
    }
    if (!c.empty()) reason += (reason.empty() ? "" : "; ") + t + ": " + c;
  }
  if (!risk_cause_.empty()) reason += (reason.empty() ? "" : "; ") + risk_cause_;
  d.stop = !reason.empty();
  d.reason = d.stop ? reason : "all inputs healthy";
  // A retreat resumes at once, but not twice within the delay: a robot
  // stopped again that soon waits like any other (no stop/go chatter).
  const bool at_once = risk_retreat_ && stop_since_ns_ - quick_resume_ns_ >= resume_delay_ns_;
  if (d.stop) {
    clear_since_ns_.reset();
    if (!last_ || !last_->stop) stop_since_ns_ = now_ns;
  } else if (last_ && last_->stop && resume_delay_ns_ > 0 && at_once) {
    quick_resume_ns_ = now_ns;
  } else if (last_ && last_->stop && resume_delay_ns_ > 0) {
    if (!clear_since_ns_) clear_since_ns_ = now_ns;
    if (now_ns - *clear_since_ns_ < resume_delay_ns_) {
      if (changed) *changed = false;
      return *last_;  // still stopped until the causes have stayed clear
    }
  }
  if (changed) *changed = !last_ || last_->stop != d.stop || (d.stop && last_->reason != d.reason);
  last_ = d;
  return d;
}

}  // namespace iplan::supervisor

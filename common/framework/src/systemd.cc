#include "iplan/framework/systemd.h"

#include <systemd/sd-daemon.h>

namespace iplan::framework::systemd {

void NotifyReady(const std::string& status) {
  sd_notify(0, ("READY=1\nSTATUS=" + status).c_str());
}

void NotifyStopping() { sd_notify(0, "STOPPING=1"); }

void NotifyStatus(const std::string& status) { sd_notify(0, ("STATUS=" + status).c_str()); }

std::chrono::microseconds WatchdogInterval() {
  uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0) return std::chrono::microseconds(usec);
  return std::chrono::microseconds(0);
}

Watchdog::Watchdog() : half_(WatchdogInterval() / 2), last_(std::chrono::steady_clock::now()) {
  if (half_.count() > 0) sd_notify(0, "WATCHDOG=1");
}

void Watchdog::Tick() {
  if (half_.count() <= 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ >= half_) {
    sd_notify(0, "WATCHDOG=1");
    last_ = now;
  }
}

}  // namespace iplan::framework::systemd

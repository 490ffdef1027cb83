// systemd notifications (sd_notify) behind our own header. All calls are
// no-ops when the process was not started by systemd (no NOTIFY_SOCKET).
#pragma once

#include <chrono>
#include <string>

namespace iplan::framework::systemd {

/// READY=1 with a status line.
void NotifyReady(const std::string& status);
/// STOPPING=1.
void NotifyStopping();
/// STATUS=...
void NotifyStatus(const std::string& status);
/// The watchdog interval systemd expects (WATCHDOG_USEC), zero when none.
std::chrono::microseconds WatchdogInterval();

/// Sends WATCHDOG=1 at half the interval systemd expects; call Tick() often
/// from the thread whose progress it vouches for.
class Watchdog {
 public:
  Watchdog();
  void Tick();

 private:
  std::chrono::microseconds half_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace iplan::framework::systemd

// Real-time scheduling and memory locking for a service process (issue 17):
// node.realtime_priority and node.lock_memory. Internal to the framework.
#pragma once

#include <string>
#include <vector>

namespace iplan::framework::internal {

/// Puts the calling thread (the service's main thread, before the DDS
/// participant starts its threads, which inherit it) under SCHED_FIFO at
/// `priority` (1-99; 0: leaves the default scheduler), and, with
/// `lock_memory`, locks every present and future page (mlockall) so the
/// executor never waits for a page-in. Returns one line per request that
/// the system refused, saying what to grant (the process keeps running on
/// the default scheduler / unlocked memory); empty when all took effect.
std::vector<std::string> ApplyRealtime(int priority, bool lock_memory);

}  // namespace iplan::framework::internal

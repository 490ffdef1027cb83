#include "realtime.h"

#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace iplan::framework::internal {

std::vector<std::string> ApplyRealtime(int priority, bool lock_memory) {
  std::vector<std::string> refused;
  if (priority > 0) {
    sched_param p{};
    p.sched_priority = priority;
    if (sched_setscheduler(0, SCHED_FIFO, &p) != 0) {
      refused.push_back("node.realtime_priority " + std::to_string(priority) + ": SCHED_FIFO refused (" +
                        std::strerror(errno) +
                        "); grant it with LimitRTPRIO=" + std::to_string(priority) +
                        " in the systemd unit (or CAP_SYS_NICE); running on the default scheduler");
    }
  }
  if (lock_memory && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    refused.push_back(std::string("node.lock_memory: mlockall refused (") + std::strerror(errno) +
                      "); grant it with LimitMEMLOCK=infinity in the systemd unit (or CAP_IPC_LOCK); "
                      "running with pageable memory");
  }
  return refused;
}

}  // namespace iplan::framework::internal

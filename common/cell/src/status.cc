#include "iplan/cell/status.h"

namespace iplan::cell {

const char* ToString(Verdict v) {
  switch (v) {
    case Verdict::kOk: return "OK";
    case Verdict::kSlowDown: return "SLOW_DOWN";
    case Verdict::kProtectiveStop: return "PROTECTIVE_STOP";
  }
  return "UNKNOWN";
}

const char* ToString(TaskStatus s) {
  switch (s) {
    case TaskStatus::kSucceeded: return "SUCCEEDED";
    case TaskStatus::kFailed: return "FAILED";
    case TaskStatus::kCancelled: return "CANCELLED";
  }
  return "UNKNOWN";
}

}  // namespace iplan::cell

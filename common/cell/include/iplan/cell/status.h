// The cell's two status vocabularies, shared by the services that produce
// and consume them. On the wire they are octets (idl/iplan_msgs.idl:
// CollisionRisk::OK.., TaskOutcome::SUCCEEDED..); services/common/adapters.h
// converts by name, never by number.
#pragma once

namespace iplan::cell {

/// Collision risk's verdict on the executing trajectory (METHOD 7).
enum class Verdict { kOk, kSlowDown, kProtectiveStop };
/// "OK", "SLOW_DOWN", "PROTECTIVE_STOP" (the IDL constants' names).
const char* ToString(Verdict v);

/// How a task of the trajectory optimiser ended.
enum class TaskStatus { kSucceeded, kFailed, kCancelled };
/// "SUCCEEDED", "FAILED", "CANCELLED" (the IDL constants' names).
const char* ToString(TaskStatus s);

}  // namespace iplan::cell

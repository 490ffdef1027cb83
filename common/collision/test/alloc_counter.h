// Test helper: counts heap allocations (global operator new) while enabled,
// to check that hot paths do not allocate (as Pinocchio's unit tests do).
#pragma once

namespace iplan::collision::test_support {

/// Starts counting from zero.
void StartCountingAllocations();
/// Stops counting and returns the number of allocations since the start.
long StopCountingAllocations();

}  // namespace iplan::collision::test_support

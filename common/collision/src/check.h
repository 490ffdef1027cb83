// Internal always-on contract check (our bug or a broken caller contract):
// prints file, line and condition and aborts. Not part of the public API.
#pragma once

#include <cstdio>
#include <cstdlib>

#define IPLAN_COLLISION_DEMAND(cond)                                             \
  do {                                                                           \
    if (!(cond)) {                                                               \
      std::fprintf(stderr, "%s:%d: IPLAN_COLLISION_DEMAND failed: %s\n", __FILE__, \
                   __LINE__, #cond);                                             \
      std::abort();                                                              \
    }                                                                            \
  } while (false)

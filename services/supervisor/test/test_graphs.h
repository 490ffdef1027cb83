// The small task graph the supervisor's tests share: two human actions,
// two picks and a place that needs both, and (for anticipation) the
// person's own graph over those actions, with uncertain branches.
#pragma once

#include "services/supervisor/core/human_graph.h"
#include "services/supervisor/core/task_planner.h"

namespace iplan::supervisor::testing {

// reach_bin lasts 2-4 s and is followed by assemble (0.8) or reach_bin
// again (0.2); assemble lasts 1-3 s and is followed by reach_bin.
inline HumanGraph SmallPerson() {
  HumanGraph g;
  g.start = {{"reach_bin", 0.5}, {"assemble", 0.5}};
  g.actions = {{"reach_bin", {{2.0, 4.0}, {{"assemble", 0.8}, {"reach_bin", 0.2}}}},
               {"assemble", {{1.0, 3.0}, {{"reach_bin", 1.0}}}}};
  return g;
}

// pick_left conflicts with reach_bin, place with assemble; no person graph.
inline TaskGraph SmallGraph() {
  TaskGraph g;
  g.human_actions = {"reach_bin", "assemble"};
  g.tasks = {{"pick_left", {0.1}, {}, {"reach_bin"}},
             {"pick_right", {0.2}, {}, {}},
             {"place", {0.3}, {"pick_left", "pick_right"}, {"assemble"}}};
  return g;
}

}  // namespace iplan::supervisor::testing

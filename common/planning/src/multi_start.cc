// Parallel multi-start (METHOD.md section 5): N seeded optimisers on up to
// num_threads threads, and the choice of the winner.
#include <algorithm>
#include <atomic>
#include <thread>

#include "planner_model.h"

namespace iplan::planning::internal {

// With early_stop_interval = K > 0 the optimisers advance in rounds of K
// iterations; after each round (all optimisers at the same iteration
// budget) every optimiser is checked, and if one is feasible and safe all
// stop. The decision uses only the optimisers' states at the round's end,
// never the order in which threads finish, so the result is the same for
// any thread count. K = 0: one round, every optimiser runs to convergence.
std::vector<Candidate> PlannerModel::RunOptimizers(const Problem& at, int num_opt, int num_threads,
                                                   std::uint64_t seed, Clock::time_point t0) const {
  const int workers = std::max(1, std::min(num_threads <= 0 ? num_opt : num_threads, num_opt));
  const int K = params.early_stop_interval > 0 ? params.early_stop_interval : params.max_iterations;
  std::vector<OptimizerState> st(num_opt);
  std::vector<Workspace> wss(workers);
  for (auto& ws : wss) PrepareWorkspace(at, &ws);
  for (int round = 1;; ++round) {
    const int until = round * K;
    std::atomic<int> next{0};
    auto work = [&](int t) {
      Workspace* ws = &wss[t];
      for (int o = next.fetch_add(1); o < num_opt; o = next.fetch_add(1)) {
        OptimizerState& s = st[o];
        // Out of time, optimisers not yet started are left out (an
        // optimiser that never started has no candidate: cost infinity).
        if (!s.started && o > 0 && at.OutOfTime()) continue;
        if (!s.started) StartOptimizer(at, o, seed, ws, &s);
        IterateOptimizer(at, until, ws, &s);
        CheckOptimizer(at, ws, &s, t0);
      }
    };
    if (workers == 1) {
      work(0);
    } else {
      std::vector<std::thread> threads;
      for (int t = 0; t < workers; ++t) threads.emplace_back(work, t);
      for (auto& t : threads) t.join();
    }
    bool all_done = true, any_ok = false;
    for (const auto& s : st) {
      all_done = all_done && s.done;
      any_ok = any_ok || (s.c.static_ok && s.c.safe);
    }
    if (all_done || any_ok || until >= params.max_iterations || at.OutOfTime()) break;
  }
  std::vector<Candidate> out(num_opt);
  for (int o = 0; o < num_opt; ++o) out[o] = std::move(st[o].c);
  return out;
}

// The winner is the lowest-cost feasible and safe candidate; the reference
// (for waits and failure reports) the lowest-cost statically feasible one.
Selection PlannerModel::Select(const std::vector<Candidate>& cands) {
  Selection sel;
  for (int o = 0; o < static_cast<int>(cands.size()); ++o) {
    const auto& c = cands[o];
    if (c.static_ok && c.safe) {
      ++sel.num_feasible;
      if (sel.first_feasible_time < 0.0 || c.first_feasible_time < sel.first_feasible_time)
        sel.first_feasible_time = c.first_feasible_time;
      if (sel.winner < 0 || c.cost < cands[sel.winner].cost) sel.winner = o;
    }
    if (c.static_ok && (sel.reference < 0 || c.cost < cands[sel.reference].cost)) sel.reference = o;
  }
  return sel;
}

}  // namespace iplan::planning::internal

#include "episode_tally.h"

#include <algorithm>
#include <limits>
#include <sstream>
#include <utility>

#include "fixed_text.h"

namespace iplan::cli {

void EpisodeTally::Started(uint32_t task_id, int episode, const std::string& name, double t) {
  if (episode < 1 || !tasks_.emplace(task_id, Task{episode, false}).second) return;  // a re-sent command
  Episode& ep = episodes_[episode];
  if (ep.start < 0) {
    ep.number = episode;
    ep.start = t;
  }
  current_episode_ = episode;
  current_task_ = name;
}

std::vector<std::string> EpisodeTally::Ended(uint32_t task_id, Ending ending, const std::string& name,
                                             double delay_s, const std::string& reason, double t) {
  std::vector<std::string> events;
  const auto it = tasks_.find(task_id);
  if (it == tasks_.end()) return events;
  if (std::exchange(it->second.ended, true)) {
    ++repeated_outcomes_;
    return events;
  }
  Episode& ep = episodes_[it->second.episode];
  ep.waiting += delay_s;
  if (ending == Ending::kSucceeded) {
    ++ep.succeeded;
    ++succeeded_tasks_;
    ep.order.push_back(name);
  } else {
    ++ep.failed;
    ++failed_tasks_;
    events.push_back("task '" + name + "' " + (ending == Ending::kFailed ? "failed" : "cancelled") +
                     (reason.empty() ? "" : ": " + reason));
  }
  current_task_.clear();
  if (!ep.done && ep.succeeded == num_tasks_) {
    ep.done = true;
    ep.end = t;
    std::ostringstream s;
    s << "episode " << ep.number << " done in " << Fixed(ep.completion(), 1) << " s, robot waiting "
      << Fixed(ep.waiting, 1) << " s:";
    for (const auto& task : ep.order) s << " " << task;
    events.push_back(s.str());
  }
  return events;
}

int EpisodeTally::completed_episodes() const {
  return static_cast<int>(
      std::count_if(episodes_.begin(), episodes_.end(), [](const auto& e) { return e.second.done; }));
}

double EpisodeTally::first_task_s() const {
  return episodes_.empty() ? std::numeric_limits<double>::infinity() : episodes_.begin()->second.start;
}

}  // namespace iplan::cli

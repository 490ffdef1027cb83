// `iplan demo`'s count of episodes and tasks, from the task commands the
// supervisor sends and the outcomes the trajectory optimiser returns.
//
// A task is one id; its outcome counts once. The trajectory optimiser
// answers a repeated command of a task that has ended with that task's
// outcome again (the supervisor re-sends while it waits, and the first
// outcome may have been lost; trajopt_service.cc), so the same outcome can
// arrive twice. Counted twice, it once ended the demo's last episode a task
// early: the repeat of `fetch_left` made four tasks look like five, the
// summary said 6 of 6 episodes and 30 tasks while the supervisor had
// finished 29, and `home` never ran. Repeats are counted apart
// (repeated_outcomes()).
//
// Times in s since the demo started. No DDS types; not thread-safe.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace iplan::cli {

/// One episode of the task graph, as the demo saw it.
struct Episode {
  int number = 0;
  double start = -1, end = -1;  ///< s since the demo started; end -1 until done
  int succeeded = 0, failed = 0;
  double waiting = 0;  ///< s, sum of its tasks' delays
  std::vector<std::string> order;  ///< the tasks that succeeded, in the order they did
  bool done = false;  ///< every task of the graph succeeded
  double completion() const { return end - start; }
};

class EpisodeTally {
 public:
  /// How a task ended.
  enum class Ending { kSucceeded, kFailed, kCancelled };

  /// num_tasks: the tasks of the graph; an episode is done when that many
  /// distinct tasks of it have succeeded.
  explicit EpisodeTally(int num_tasks) : num_tasks_(num_tasks) {}

  /// A task's start command (episode >= 1) at t. A command whose id was
  /// seen before (re-sent) changes nothing.
  void Started(uint32_t task_id, int episode, const std::string& name, double t);

  /// A task's outcome at t (delay_s: how long it was held up, s). Returns
  /// the event lines it makes: a failed or cancelled task, an episode done.
  /// An outcome of a task never started here, or one already counted, makes
  /// none and changes nothing but the count of repeats.
  std::vector<std::string> Ended(uint32_t task_id, Ending ending, const std::string& name, double delay_s,
                                 const std::string& reason, double t);

  const std::map<int, Episode>& episodes() const { return episodes_; }
  int completed_episodes() const;
  /// s since the demo started of the first task command; infinity before it.
  double first_task_s() const;
  int current_episode() const { return current_episode_; }
  /// The running task's name, empty between tasks.
  const std::string& current_task() const { return current_task_; }
  int succeeded_tasks() const { return succeeded_tasks_; }
  int failed_tasks() const { return failed_tasks_; }
  /// Outcomes of tasks whose outcome had already been counted.
  int repeated_outcomes() const { return repeated_outcomes_; }

 private:
  struct Task {
    int episode = 0;
    bool ended = false;  // its outcome is counted
  };
  int num_tasks_;
  std::map<uint32_t, Task> tasks_;  // by task id
  std::map<int, Episode> episodes_;
  int current_episode_ = 0;
  std::string current_task_;
  int succeeded_tasks_ = 0, failed_tasks_ = 0, repeated_outcomes_ = 0;
};

}  // namespace iplan::cli

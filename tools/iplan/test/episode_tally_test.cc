// The demo's count of episodes: a task's outcome counts once, however often
// it arrives.
#include "episode_tally.h"

#include <cmath>

#include <gtest/gtest.h>

namespace iplan::cli {
namespace {

using Ending = EpisodeTally::Ending;

// Starts and ends task `id` of episode `e` at t, t + 1.
std::vector<std::string> RunTask(EpisodeTally& tally, uint32_t id, int e, const std::string& name, double t) {
  tally.Started(id, e, name, t);
  return tally.Ended(id, Ending::kSucceeded, name, 0.25, "", t + 1);
}

TEST(EpisodeTally, AnEpisodeIsDoneWhenEveryTaskHasSucceeded) {
  EpisodeTally tally(3);
  EXPECT_TRUE(std::isinf(tally.first_task_s()));
  EXPECT_TRUE(RunTask(tally, 1, 1, "fetch_right", 2.0).empty());
  EXPECT_TRUE(RunTask(tally, 2, 1, "hand_over", 3.0).empty());
  const std::vector<std::string> events = RunTask(tally, 3, 1, "home", 4.0);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0], "episode 1 done in 3.0 s, robot waiting 0.8 s: fetch_right hand_over home");
  const Episode& ep = tally.episodes().at(1);
  EXPECT_TRUE(ep.done);
  EXPECT_DOUBLE_EQ(ep.completion(), 3.0);
  EXPECT_DOUBLE_EQ(ep.waiting, 0.75);
  EXPECT_EQ(tally.completed_episodes(), 1);
  EXPECT_EQ(tally.succeeded_tasks(), 3);
  EXPECT_DOUBLE_EQ(tally.first_task_s(), 2.0);
}

// The demo's depth-only run of 2026-12-07 22:55 UTC: trajopt answered a
// repeated `fetch_left` command with its outcome again; counted twice, the
// episode ended after four tasks and `home` never ran.
TEST(EpisodeTally, ARepeatedOutcomeCountsOnce) {
  EpisodeTally tally(3);
  RunTask(tally, 7, 6, "fetch_left", 0.0);
  tally.Started(7, 6, "fetch_left", 0.5);  // re-sent command: no new task
  EXPECT_TRUE(tally.Ended(7, Ending::kSucceeded, "fetch_left", 0.25, "", 1.5).empty());
  EXPECT_EQ(tally.repeated_outcomes(), 1);
  EXPECT_EQ(tally.succeeded_tasks(), 1);
  EXPECT_TRUE(RunTask(tally, 8, 6, "hand_over", 2.0).empty());
  EXPECT_EQ(tally.completed_episodes(), 0) << "two distinct tasks of three";
  const Episode& ep = tally.episodes().at(6);
  EXPECT_EQ(ep.order, (std::vector<std::string>{"fetch_left", "hand_over"}));
  EXPECT_DOUBLE_EQ(ep.waiting, 0.5) << "the repeat's delay is not added again";
  EXPECT_EQ(RunTask(tally, 9, 6, "home", 4.0).size(), 1u);
  EXPECT_EQ(tally.completed_episodes(), 1);
  EXPECT_DOUBLE_EQ(tally.episodes().at(6).start, 0.0) << "the re-sent command does not restart the episode";
}

TEST(EpisodeTally, FailuresAreEventsAndAnUnknownTaskChangesNothing) {
  EpisodeTally tally(2);
  tally.Started(1, 1, "hand_over", 0.0);
  EXPECT_EQ(tally.current_task(), "hand_over");
  EXPECT_EQ(tally.current_episode(), 1);
  const auto events = tally.Ended(1, Ending::kFailed, "hand_over", 0.0, "no safe trajectory", 1.0);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0], "task 'hand_over' failed: no safe trajectory");
  EXPECT_EQ(tally.failed_tasks(), 1);
  EXPECT_TRUE(tally.current_task().empty());
  EXPECT_EQ(tally.Ended(2, Ending::kCancelled, "x", 0.0, "", 1.0).size(), 0u);  // never started here
  EXPECT_EQ(tally.repeated_outcomes(), 0);
  tally.Started(3, 0, "home", 2.0);  // episode 0: not an episode's task
  EXPECT_TRUE(tally.Ended(3, Ending::kSucceeded, "home", 0.0, "", 3.0).empty());
  EXPECT_EQ(tally.succeeded_tasks(), 0);
  EXPECT_EQ(tally.episodes().size(), 1u);
}

}  // namespace
}  // namespace iplan::cli

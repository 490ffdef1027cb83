// The person's own task graph and the anticipating task choice (our
// extension of METHOD 6): the graph is validated and loaded strictly; drawn
// sequences follow its probabilities and durations (seeded); the forecast
// of the person's actions is the semi-Markov chain's; the choice picks the
// task that will not conflict with what the person is predicted to do
// *next*, where METHOD 6's choice (and one looking at the current action
// only) picks the conflicting one; task durations are learned and saved;
// the duration weight (our extension of the reward) learns the order that
// travels less; the travel weight chooses the nearer task.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "services/supervisor/core/human_graph.h"
#include "services/supervisor/core/task_planner.h"
#include "services/supervisor/test/test_graphs.h"

namespace iplan::supervisor {
namespace {

HumanGraph Person() { return testing::SmallPerson(); }

TaskGraph Graph() {
  TaskGraph g = testing::SmallGraph();
  g.human_graph = Person();
  return g;
}

TEST(HumanGraph, ValidationNamesTheProblem) {
  const std::vector<std::string> actions = {"reach_bin", "assemble"};
  EXPECT_EQ(Person().Validate(actions), "");
  EXPECT_EQ(HumanGraph{}.Validate(actions), "");  // none given
  HumanGraph g = Person();
  g.actions[0].second.next = {{"assemble", 0.5}, {"reach_bin", 0.25}};
  EXPECT_EQ(g.Validate(actions), "human_graph.actions.reach_bin.next has probabilities summing to 0.75, not 1");
  g = Person();
  g.actions[1].second.duration = {3.0, 1.0};
  EXPECT_EQ(g.Validate(actions),
            "human_graph.actions.assemble.duration must be [least, most] with 0 < least <= most, got [3.0, 1.0]");
  g = Person();
  g.start = {{"dance", 1.0}};
  EXPECT_EQ(g.Validate(actions), "human_graph.start names unknown human action 'dance'");
  g = Person();
  g.actions.pop_back();
  EXPECT_EQ(g.Validate(actions),
            "human_graph.actions.reach_bin.next names 'assemble', which has no entry in human_graph.actions");
  // The task graph checks its human graph.
  TaskGraph t = Graph();
  t.human_graph.actions[1].second.next = {{"reach_bin", 1.5}};
  EXPECT_EQ(t.Validate(), "human_graph.actions.assemble.next gives 'reach_bin' a probability outside [0, 1]");
}

TEST(HumanGraph, LoadsFromTheTaskGraphFileStrictly) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("iplan-human-graph-" + std::to_string(getpid()) + ".yaml")).string();
  std::ofstream(path) << "human_actions: [reach, work]\n"
                         "robot_tasks:\n"
                         "  - {name: fetch, goal: [0.1]}\n"
                         "human_graph:\n"
                         "  start: {reach: 1.0}\n"
                         "  actions:\n"
                         "    reach: {duration: [2, 4], next: {work: 1.0}}\n"
                         "    work: {duration: [1, 1], next: {reach: 0.25, work: 0.75}}\n";
  const TaskGraph g = LoadTaskGraph(path);
  ASSERT_EQ(g.human_graph.actions.size(), 2u);
  EXPECT_EQ(g.human_graph.actions[1].first, "work");
  EXPECT_EQ(g.human_graph.actions[1].second.next.at("work"), 0.75);
  std::ofstream(path) << "human_actions: [reach]\n"
                         "robot_tasks:\n"
                         "  - {name: fetch, goal: [0.1]}\n"
                         "human_graph:\n"
                         "  actions:\n"
                         "    reach: {duration: [2, 4], nxt: {reach: 1.0}}\n";
  try {
    LoadTaskGraph(path);
    FAIL() << "a misspelt key was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nxt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

// Uniform numbers in [0, 1) from a seeded generator (its bits, not
// std::uniform_real_distribution, which differs between standard libraries).
std::function<double()> Uniform(std::mt19937_64* rng) {
  return [rng] { return static_cast<double>((*rng)() >> 11) * 0x1.0p-53; };
}

TEST(HumanGraph, DrawsFollowTheGraphsProbabilitiesAndDurations) {
  const HumanGraph g = Person();
  std::mt19937_64 rng(7);
  std::map<std::string, int> first;
  std::map<std::string, std::map<std::string, int>> transitions;
  std::map<std::string, std::pair<double, int>> durations;  // sum, count
  for (int episode = 0; episode < 2000; ++episode) {
    const std::vector<HumanActionSpan> spans = DrawHumanActions(g, 30.0, Uniform(&rng));
    ASSERT_GE(spans.size(), 2u);
    ++first[spans.front().action];
    EXPECT_LE(spans.front().start, 0.0);
    EXPECT_GT(spans.front().end(), 0.0);
    EXPECT_GE(spans.back().end(), 30.0);
    for (std::size_t i = 0; i < spans.size(); ++i) {
      const auto& d = g.actions[static_cast<std::size_t>(g.Find(spans[i].action))].second.duration;
      EXPECT_GE(spans[i].duration, d[0]);
      EXPECT_LE(spans[i].duration, d[1]);
      durations[spans[i].action].first += spans[i].duration;
      ++durations[spans[i].action].second;
      if (i > 0) {
        EXPECT_DOUBLE_EQ(spans[i].start, spans[i - 1].end());
        ++transitions[spans[i - 1].action][spans[i].action];
      }
    }
  }
  EXPECT_NEAR(first["reach_bin"] / 2000.0, 0.5, 0.03);
  const auto& from_reach = transitions["reach_bin"];
  const double n = from_reach.at("assemble") + from_reach.at("reach_bin");
  EXPECT_GT(n, 5000);
  EXPECT_NEAR(from_reach.at("assemble") / n, 0.8, 0.015);
  EXPECT_EQ(transitions["assemble"].count("assemble"), 0u);
  EXPECT_NEAR(durations["reach_bin"].first / durations["reach_bin"].second, 3.0, 0.03);
  EXPECT_NEAR(durations["assemble"].first / durations["assemble"].second, 2.0, 0.03);
  // The same seed draws the same sequence.
  std::mt19937_64 a(11), b(11);
  const auto x = DrawHumanActions(g, 20.0, Uniform(&a)), y = DrawHumanActions(g, 20.0, Uniform(&b));
  ASSERT_EQ(x.size(), y.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x[i].action, y[i].action);
    EXPECT_EQ(x[i].duration, y[i].duration);
  }
  EXPECT_THROW(DrawHumanActions(HumanGraph{}, 20.0, Uniform(&a)), std::invalid_argument);
}

TEST(HumanGraph, TheForecastIsTheSemiMarkovChains) {
  const HumanGraph g = Person();
  ActionOutlook o;
  o.belief = {{"assemble", 1.0}};
  o.elapsed = 1.0;  // assemble lasts 1-3 s: from age 1 it ends uniformly within the next 2 s
  const double dt = 0.05;
  const ActionForecast f = ForecastActions(g, o, dt, 100);
  ASSERT_EQ(f.actions, (std::vector<std::string>{"reach_bin", "assemble"}));
  ASSERT_EQ(f.p.size(), 100u);
  auto at = [&](double t, int action) { return f.p[static_cast<std::size_t>(std::lround(t / dt))][static_cast<std::size_t>(action)]; };
  EXPECT_DOUBLE_EQ(at(0.0, 1), 1.0);
  EXPECT_NEAR(at(1.0, 1), 0.5, 0.03);  // still assembling half the time, 1 s on
  EXPECT_NEAR(at(1.0, 0), 0.5, 0.03);  // assemble -> reach_bin always (reach_bin lasts at least 2 s)
  EXPECT_EQ(at(2.0, 1), 0.0);  // assembling ended by 3 s of age; reach_bin lasts past 2 s
  for (const auto& p : f.p) EXPECT_NEAR(p[0] + p[1], 1.0, 1e-9);
  // An oracle: assemble ends in 0.5 s, then reach_bin.
  o.remaining = 0.5;
  o.next = "reach_bin";
  const ActionForecast known = ForecastActions(g, o, dt, 40);
  EXPECT_DOUBLE_EQ(known.p[9][1], 1.0);
  EXPECT_DOUBLE_EQ(known.p[11][0], 1.0);
  // Without a graph the belief lasts; actions the graph does not know too.
  ActionOutlook unknown;
  unknown.belief = {{"wave", 0.3}, {"assemble", 0.7}};
  const ActionForecast kept = ForecastActions(HumanGraph{}, unknown, dt, 10);
  ASSERT_EQ(kept.actions.size(), 2u);
  for (const auto& p : kept.p) EXPECT_NEAR(p[0] + p[1], 1.0, 1e-12);
  const ActionForecast mixed = ForecastActions(g, unknown, dt, 80);
  ASSERT_EQ(mixed.actions.back(), "wave");
  EXPECT_DOUBLE_EQ(mixed.p.back().back(), 0.3);
}

TEST(HumanGraph, AnActionMetPartWayThroughIsAgedByItsSurvival) {
  // assemble lasts 1-3 s (uniform). Found in progress, at least `elapsed`
  // old, its age has density proportional to the survival S from `elapsed`
  // on, so P(still assembling t later) = int S(a + t) / int S(a) over a >=
  // elapsed; with the age known exactly it is S(elapsed + t) / S(elapsed).
  const HumanGraph g = Person();
  const double dt = 0.05;
  auto still = [&](double elapsed, bool at_least, double t) {
    ActionOutlook o;
    o.belief = {{"assemble", 1.0}};
    o.elapsed = elapsed;
    o.elapsed_at_least = at_least;
    const ActionForecast f = ForecastActions(g, o, dt, 80);
    for (const auto& p : f.p) EXPECT_NEAR(p[0] + p[1], 1.0, 1e-9);
    return f.p[static_cast<std::size_t>(std::lround(t / dt))][1];
  };
  EXPECT_NEAR(still(0.0, false, 1.5), 0.75, 0.03);  // S(1.5)
  EXPECT_NEAR(still(0.0, true, 1.5), 0.28, 0.03);   // (1.5^2 / 4) / 2
  EXPECT_NEAR(still(0.0, true, 0.5), 0.75, 0.03);   // (0.5 + 1) / 2
  EXPECT_NEAR(still(2.0, false, 0.5), 0.5, 0.03);   // S(2.5) / S(2)
  EXPECT_NEAR(still(2.0, true, 0.5), 0.25, 0.03);   // (0.5^2 / 4) / (1 / 4)
  // Past its most it ends at once either way.
  EXPECT_EQ(still(3.5, true, 0.1), 0.0);
  EXPECT_EQ(still(3.5, false, 0.1), 0.0);
}

TEST(ActionTracker, AShortFlipKeepsTheAgeAndAChangeIsDatedWhenItBegan) {
  ActionTrackerParams params;
  params.action_switch_confirm = 0.5;
  params.action_recognition_delay = 0.7;
  ActionTracker tracker(params);
  const std::map<std::string, double> a = {{"reach", 0.8}, {"idle", 0.2}}, b = {{"reach", 0.3}, {"idle", 0.7}};
  EXPECT_EQ(tracker.action(), "");
  EXPECT_EQ(tracker.Elapsed(1.0), 0.0);
  EXPECT_FALSE(tracker.Outlook({}, 1.0).elapsed_at_least);
  // The first belief: begun before it, so at least this old, no delay added.
  tracker.Update(10.0, a);
  tracker.Update(11.0, a);
  EXPECT_EQ(tracker.action(), "reach");
  EXPECT_FALSE(tracker.StartSeen());
  EXPECT_DOUBLE_EQ(tracker.Elapsed(11.0), 1.0);
  ActionOutlook o = tracker.Outlook(a, 11.0);
  EXPECT_TRUE(o.elapsed_at_least);
  EXPECT_DOUBLE_EQ(o.elapsed, 1.0);
  EXPECT_EQ(o.belief, a);
  // A flip shorter than the confirmation: still reaching, the age goes on.
  for (double t : {12.0, 12.1, 12.2, 12.4}) tracker.Update(t, b);
  tracker.Update(12.5, a);
  EXPECT_EQ(tracker.action(), "reach");
  EXPECT_DOUBLE_EQ(tracker.Elapsed(12.5), 2.5);
  // A lasting one: idle from when it began (13.0), plus the recognition delay.
  for (double t : {13.0, 13.2, 13.4}) tracker.Update(t, b);
  EXPECT_EQ(tracker.action(), "reach");
  tracker.Update(13.5, b);
  EXPECT_EQ(tracker.action(), "idle");
  EXPECT_TRUE(tracker.StartSeen());
  EXPECT_DOUBLE_EQ(tracker.Elapsed(14.0), 1.0 + 0.7);
  EXPECT_FALSE(tracker.Outlook(b, 14.0).elapsed_at_least);
  // An empty belief forgets: the next action starts unseen again.
  tracker.Update(15.0, {});
  EXPECT_EQ(tracker.action(), "");
  tracker.Update(16.0, a);
  EXPECT_FALSE(tracker.StartSeen());
  EXPECT_DOUBLE_EQ(tracker.Elapsed(16.5), 0.5);
}

TEST(ActionTracker, WithTheDefaultsEveryFlipIsAChange) {
  ActionTracker tracker;
  tracker.Update(0.0, {{"reach", 1.0}});
  tracker.Update(1.0, {{"idle", 1.0}});
  EXPECT_EQ(tracker.action(), "idle");
  EXPECT_TRUE(tracker.StartSeen());
  EXPECT_DOUBLE_EQ(tracker.Elapsed(1.5), 0.5);
}

TEST(ActionTracker, BadParametersAreRefusedWithTheKey) {
  ActionTrackerParams p;
  EXPECT_EQ(p.Validate(), "");
  p.action_switch_confirm = -0.1;
  EXPECT_NE(p.Validate().find("action_switch_confirm"), std::string::npos);
  EXPECT_THROW(ActionTracker{p}, std::invalid_argument);
  p = {};
  p.action_recognition_delay = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(p.Validate().find("action_recognition_delay"), std::string::npos);
  EXPECT_THROW(ActionTracker{p}, std::invalid_argument);
}

TEST(TaskPlanner, TheAnticipatingChoiceAvoidsTheActionPredictedNext) {
  // The person assembles, 1 s into an action of 1-3 s, and then reaches into
  // the bin (always). pick_left (the bin) does not conflict with assembling,
  // so METHOD 6's choice takes it (the tie goes to the harmony with the
  // current action, then to the index); over its 3 s the person is expected
  // to be at the bin about 1.9 of them. The anticipating choice takes
  // pick_right, which conflicts with nothing.
  ActionOutlook outlook;
  outlook.belief = {{"assemble", 1.0}};
  outlook.elapsed = 1.0;
  QLearningParams method;
  method.learning = false;
  TaskPlanner plain(Graph(), method);
  EXPECT_EQ(plain.Choose(outlook), 0);
  QLearningParams anticipating = method;
  anticipating.anticipation_weight = 1.0;
  TaskPlanner planner(Graph(), anticipating);
  EXPECT_NEAR(planner.ExpectedConflict(0, outlook), 1.9, 0.1);
  EXPECT_DOUBLE_EQ(planner.ExpectedConflict(1, outlook), 0.0);
  EXPECT_EQ(planner.Choose(outlook), 1);
  // Looking at the current action only (no person's graph), it cannot know.
  TaskGraph current_only = Graph();
  current_only.human_graph = HumanGraph{};
  TaskPlanner blind(current_only, anticipating);
  EXPECT_DOUBLE_EQ(blind.ExpectedConflict(0, outlook), 0.0);
  EXPECT_EQ(blind.Choose(outlook), 0);
  // Nothing known of the person: Q alone.
  EXPECT_EQ(planner.Choose(ActionOutlook{}), 0);
  // The task's own duration counts: pick_left known to take 0.5 s is
  // expected to meet the person at the bin for only about 0.05 s of it.
  planner.ObserveDuration(0, 0.5);
  EXPECT_DOUBLE_EQ(planner.TaskDuration(0), 0.5);
  EXPECT_NEAR(planner.ExpectedConflict(0, outlook), 0.05, 0.02);
}

TEST(TaskPlanner, LookingFurtherAheadFitsTheConflictingTaskBeforeTheAction) {
  // The person rests for 3 s more, then works for 10 s. Hand-over (2.5 s)
  // conflicts with working; filler (3 s) with nothing. One task ahead, both
  // are clear now and the index picks filler, which leaves the hand-over to
  // the work; two tasks ahead, the hand-over first fits before the work.
  TaskGraph g;
  g.human_actions = {"rest", "work"};
  g.tasks = {{"filler", {0.1}, {}, {}}, {"hand_over", {0.2}, {}, {"work"}}};
  g.human_graph.start = {{"rest", 1.0}};
  g.human_graph.actions = {{"rest", {{3.0, 3.0}, {{"work", 1.0}}}}, {"work", {{10.0, 10.0}, {{"rest", 1.0}}}}};
  ActionOutlook outlook;
  outlook.belief = {{"rest", 1.0}};
  QLearningParams params;
  params.learning = false;
  params.anticipation_weight = 1.0;
  TaskPlanner one(g, params);
  params.anticipation_depth = 2;
  TaskPlanner two(g, params);
  for (TaskPlanner* p : {&one, &two}) {
    p->ObserveDuration(0, 3.0);
    p->ObserveDuration(1, 2.5);
  }
  EXPECT_NEAR(one.AnticipatedConflict(0, outlook), 0.0, 1e-9);
  EXPECT_NEAR(one.AnticipatedConflict(1, outlook), 0.0, 1e-9);
  EXPECT_EQ(one.Choose(outlook), 0);
  EXPECT_NEAR(two.AnticipatedConflict(0, outlook), 2.5, 1e-9);  // filler, then the hand-over into the work
  EXPECT_NEAR(two.AnticipatedConflict(1, outlook), 0.0, 1e-9);
  EXPECT_EQ(two.Choose(outlook), 1);
  params.anticipation_depth = 0;
  EXPECT_EQ(params.Validate(), "anticipation_depth must be in [1, 8]");
}

TEST(TaskPlanner, TaskDurationsAreLearnedAndSavedWithTheTable) {
  QLearningParams params;
  params.task_duration_prior = 4.0;
  TaskPlanner p(Graph(), params);
  EXPECT_DOUBLE_EQ(p.TaskDuration(2), 4.0);
  p.ObserveDuration(2, 2.0);
  p.ObserveDuration(2, 3.0);
  p.ObserveDuration(2, std::nan(""));  // ignored
  p.ObserveDuration(2, -1.0);          // ignored
  EXPECT_DOUBLE_EQ(p.TaskDuration(2), 2.5);
  const std::string path =
      (std::filesystem::temp_directory_path() / ("iplan-durations-" + std::to_string(getpid()) + ".bin")).string();
  p.Save(path);
  TaskPlanner q(Graph(), params);
  std::string note;
  ASSERT_TRUE(q.Load(path, &note)) << note;
  EXPECT_DOUBLE_EQ(q.TaskDuration(2), 2.5);
  EXPECT_DOUBLE_EQ(q.TaskDuration(0), 4.0);
  q.ObserveDuration(2, 4.0);  // the count came back too: the mean of three
  EXPECT_DOUBLE_EQ(q.TaskDuration(2), 3.0);
  params.anticipation_weight = -1;
  EXPECT_EQ(params.Validate(), "anticipation_weight must be >= 0");
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".bak");
}

TEST(TaskPlanner, TheDurationWeightLearnsTheOrderThatTravelsLess) {
  // No task waits. Each takes 1 s of motion, except pick_right right after
  // pick_left: 4 s (the robot is far from it there). So pick_right,
  // pick_left, place takes 3 s and pick_left, pick_right, place 6 s.
  // METHOD 6's reward (duration_weight 0) cannot tell the orders apart; with
  // the weight the table learns to start with pick_right.
  auto learn = [](double duration_weight) {
    QLearningParams params;
    params.seed = 3;
    params.duration_weight = duration_weight;
    auto p = std::make_unique<TaskPlanner>(Graph(), params);
    for (int episode = 0; episode < 300; ++episode) {
      p->ResetEpisode();
      int last = -1;
      while (!p->episode_done()) {
        const int t = p->Choose({});
        p->Complete(t, true, 0.0, {}, t == 1 && last == 0 ? 4.0 : 1.0);
        last = t;
      }
    }
    return p;
  };
  const auto method6 = learn(0.0);
  EXPECT_NEAR(method6->Q(0, 0), method6->Q(0, 1), 0.05);
  // Converged: Q(0, pick_right) - Q(0, pick_left) = gamma * 3 s * w_t = 0.36.
  const auto timed = learn(0.2);
  EXPECT_NEAR(timed->Q(0, 1) - timed->Q(0, 0), 0.36, 0.05);

  QLearningParams params;
  params.delay_weight = 2.0;
  params.duration_weight = 0.25;
  TaskPlanner p(Graph(), params);
  EXPECT_DOUBLE_EQ(p.Complete(1, true, 0.5, {}, 2.0), 1.0 - 2.0 * 0.5 - 0.25 * 2.0);
  EXPECT_DOUBLE_EQ(p.Complete(0, true, 0.0, {}, -3.0), 1.0);  // a negative motion time is no bonus
  EXPECT_TRUE(std::isnan(p.Complete(2, true, 0.0, {}, std::nan(""))));
  EXPECT_EQ(p.refused_outcomes(), 1u);

  params.duration_weight = -1.0;
  EXPECT_EQ(params.Validate(), "duration_weight must be >= 0");
  params.duration_weight = std::numeric_limits<double>::infinity();
  EXPECT_EQ(params.Validate(), "duration_weight must be >= 0");
}

TEST(TaskPlanner, TheTravelWeightChoosesTheNearerTaskFromWhereTheRobotStands) {
  // One joint: rest at 0, pick_left's goal at 2, pick_right's at 0.5 and
  // its retreat at 1.8, place (after both) at 1. No Q-values, no belief:
  // the choice is the travel's alone.
  TaskGraph g = testing::SmallGraph();
  g.human_graph = {};
  g.tasks[0].goal = {2.0};
  g.tasks[1].goal = {0.5};
  g.tasks[1].retreat = {1.8};
  g.tasks[2].goal = {1.0};
  g.tasks.push_back({"rest", {0.0}, {"place"}, {}});
  g.rest = "rest";
  QLearningParams params;
  params.learning = false;
  params.travel_weight = 1.0;
  params.travel_speed = 0.5;  // rad/s
  TaskPlanner p(g, params);
  EXPECT_DOUBLE_EQ(p.Travel(0), 4.0);  // from the rest pose: 2 rad at 0.5 rad/s
  EXPECT_DOUBLE_EQ(p.Travel(1), 1.0);
  EXPECT_EQ(p.Choose({}), 1);  // pick_right is nearer
  p.Complete(1, true, 0.0, {});
  EXPECT_EQ(p.last_task(), 1);
  EXPECT_DOUBLE_EQ(p.Travel(0), 0.4);  // from pick_right's retreat, 1.8
  p.Complete(0, false, 0.0, {});       // failed: the robot is not at pick_left
  EXPECT_EQ(p.last_task(), 1);
  p.Complete(0, true, 0.0, {});
  EXPECT_DOUBLE_EQ(p.Travel(2), 2.0);  // from pick_left's goal (no retreat), 2
  p.ResetEpisode();
  EXPECT_EQ(p.last_task(), -1);
  EXPECT_DOUBLE_EQ(p.Travel(0), 4.0);

  // Without the weight the choice is METHOD 6's: Q ties, the first task.
  params.travel_weight = 0.0;
  TaskPlanner q(g, params);
  EXPECT_EQ(q.Choose({}), 0);
  // A goal of another size (a pose not solved for this arm) travels 0.
  g.tasks[0].goal = {2.0, 0.0};
  TaskPlanner r(g, QLearningParams{});
  EXPECT_DOUBLE_EQ(r.Travel(0), 0.0);

  params.travel_weight = -1.0;
  EXPECT_EQ(params.Validate(), "travel_weight must be >= 0");
  params.travel_weight = 1.0;
  params.travel_speed = 0.0;
  EXPECT_EQ(params.Validate(), "travel_speed must be > 0");
}

TEST(TaskPlanner, TheChoiceLooksAtTheTravelOfTheWholeOrder) {
  // One joint: rest at 0, pick_left at 1, pick_right at -0.6, place (after
  // both) at -1. The nearest task first (pick_right, 0.6 rad) makes the
  // order travel 0.6 + 1.6 + 2.0 = 4.2 rad; pick_left first, 1.0 + 1.6 +
  // 0.4 = 3.0 rad. Looking one task ahead picks the nearer; looking at the
  // whole order (anticipation_depth 3), the shorter order. No belief, no
  // Q-values: the travel alone.
  TaskGraph g = testing::SmallGraph();
  g.human_graph = {};
  g.tasks[0].goal = {1.0};
  g.tasks[1].goal = {-0.6};
  g.tasks[2].goal = {-1.0};
  g.tasks.push_back({"rest", {0.0}, {"place"}, {}});
  g.rest = "rest";
  QLearningParams params;
  params.learning = false;
  params.travel_weight = 1.0;
  params.anticipation_depth = 1;
  EXPECT_EQ(TaskPlanner(g, params).Choose({}), 1);
  for (int depth : {3, 4, 8}) {  // the rest task after place changes nothing; the depth is capped by the tasks left
    params.anticipation_depth = depth;
    TaskPlanner p(g, params);
    EXPECT_EQ(p.Choose({}), 0) << "depth " << depth;
    p.Complete(0, true, 0.0, {});
    EXPECT_EQ(p.Choose({}), 1);
    p.Complete(1, true, 0.0, {});
    EXPECT_EQ(p.Choose({}), 2);
  }
  // A retreat is where the next leg starts: pick_right withdrawing to 1
  // makes pick_right first 0.6 + 0 + 2.0 = 2.6 rad, pick_left first 1.0 +
  // 1.6 + 2.0 = 4.6 rad.
  params.anticipation_depth = 3;
  g.tasks[1].retreat = {1.0};
  EXPECT_EQ(TaskPlanner(g, params).Choose({}), 1);
  // Without the travel weight nothing is looked at: METHOD 6's choice (Q
  // ties, the first task).
  params.travel_weight = 0.0;
  EXPECT_EQ(TaskPlanner(g, params).Choose({}), 0);
}

}  // namespace
}  // namespace iplan::supervisor

// The task planner (task graph, Q-learning, persistence) and the safety
// monitor of the supervisor, without DDS.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include <gtest/gtest.h>

#include "iplan/core/params.h"

#include "services/supervisor/core/safety_monitor.h"
#include "services/supervisor/core/supervisor_settings.h"
#include "services/supervisor/core/task_planner.h"
#include "services/supervisor/test/test_graphs.h"
#include "iplan/core/atomic_file.h"
#include "iplan/core/checksum.h"

namespace iplan::supervisor {
namespace {

TaskGraph Graph() { return testing::SmallGraph(); }

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("iplan-sup-" + std::to_string(getpid()) + "-" + name)).string();
}

TEST(TaskGraph, ValidationNamesTheProblem) {
  TaskGraph g = Graph();
  EXPECT_EQ(g.Validate(), "");
  g.tasks[2].after.push_back("fly");
  EXPECT_EQ(g.Validate(), "task 'place' comes after unknown task 'fly'");
  g = Graph();
  g.tasks[0].after = {"place"};
  EXPECT_EQ(g.Validate(), "the precedence of task 'pick_left' has a cycle");
  g = Graph();
  g.tasks[1].conflicts_with = {"dance"};
  EXPECT_EQ(g.Validate(), "task 'pick_right' conflicts with unknown human action 'dance'");
  g = Graph();
  g.tasks[2].retreat = {0.0, 0.1};
  EXPECT_EQ(g.Validate(), "task 'place' has a retreat of 2 joint positions and a goal of 1");
  g.tasks[2].retreat = {std::nan("")};
  EXPECT_EQ(g.Validate(), "task 'place' has a non-finite retreat");
  g = Graph();
  g.tasks[0].goal = {std::numeric_limits<double>::infinity()};
  EXPECT_EQ(g.Validate(), "task 'pick_left' has a non-finite goal");
}

TEST(TaskGraph, LoadsRetreatsAndNamesTheFileOnErrors) {
  const std::string path = TempPath("graph.yaml");
  std::ofstream(path) << "human_actions: [assemble]\n"
                         "robot_tasks:\n"
                         "  - name: fetch\n"
                         "    goal: [0.1, 0.2]\n"
                         "  - name: hand_over\n"
                         "    goal: [0.3, 0.4]\n"
                         "    retreat: [0.0, -0.5]\n"
                         "    after: [fetch]\n"
                         "    conflicts_with: [assemble]\n";
  const TaskGraph g = LoadTaskGraph(path);
  ASSERT_EQ(g.tasks.size(), 2u);
  EXPECT_TRUE(g.tasks[0].retreat.empty());
  EXPECT_EQ(g.tasks[1].retreat, (std::vector<double>{0.0, -0.5}));
  std::ofstream(path) << "robot_tasks:\n"
                         "  - name: hand_over\n"
                         "    goal: [0.3, 0.4]\n"
                         "    retreat: [0.0]\n";
  try {
    LoadTaskGraph(path);
    ADD_FAILURE() << "a retreat of the wrong size was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": task 'hand_over' has a retreat of 1 joint positions and a goal of 2");
  }
  std::filesystem::remove(path);
}

TEST(TaskGraph, AKeyWrittenTwiceIsAnError) {
  // yaml-cpp would keep the first goal and ignore the corrected one below it.
  const std::string path = TempPath("twice.yaml");
  std::ofstream(path) << "robot_tasks:\n"
                         "  - name: hand_over\n"
                         "    goal: [0.3, 0.4]\n"
                         "    goal: [0.5, 0.4]\n";
  try {
    LoadTaskGraph(path);
    ADD_FAILURE() << "a key written twice was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": key 'robot_tasks[0].goal': appears twice (lines 3 and 4)");
  }
  std::filesystem::remove(path);
}

TEST(TaskPlanner, PrecedenceAndHarmony) {
  TaskPlanner p(Graph(), QLearningParams{});
  EXPECT_EQ(p.Available(), (std::vector<int>{0, 1}));
  EXPECT_DOUBLE_EQ(p.Harmony(0, {{"reach_bin", 0.8}, {"assemble", 0.2}}), 0.2);
  EXPECT_DOUBLE_EQ(p.Harmony(1, {{"reach_bin", 0.8}}), 1.0);
  p.Complete(0, true, 0, {});
  EXPECT_EQ(p.Available(), (std::vector<int>{1}));
  p.Complete(1, false, 0, {});  // failed: not done
  EXPECT_EQ(p.Available(), (std::vector<int>{1}));
  p.Complete(1, true, 0, {});
  EXPECT_EQ(p.Available(), (std::vector<int>{2}));
  p.Complete(2, true, 0, {});
  EXPECT_TRUE(p.episode_done());
  EXPECT_EQ(p.Choose({}), -1);
}

TEST(TaskPlanner, LearnsToAvoidTheTaskThatCausesDelay) {
  QLearningParams params;
  params.seed = 3;
  TaskPlanner p(Graph(), params);
  // pick_left always makes the robot wait 3 s (the person works at the bin).
  for (int episode = 0; episode < 60; ++episode) {
    p.ResetEpisode();
    while (!p.episode_done()) {
      const int t = p.Choose({});
      p.Complete(t, true, t == 0 ? 3.0 : 0.0, {});
    }
  }
  EXPECT_LT(p.Q(0, 0), p.Q(0, 1));
  QLearningParams deploy = params;
  deploy.learning = false;
  const std::string path = TempPath("learned.bin");
  p.Save(path);
  TaskPlanner d(Graph(), deploy);
  std::string note;
  ASSERT_TRUE(d.Load(path, &note)) << note;
  EXPECT_EQ(d.Choose({}), 1);  // greedy: the task that did not wait first
  EXPECT_EQ(d.Q(0, 0), p.Q(0, 0));
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".bak");
}

// Plays one episode in index order; every task succeeds without delay.
void PlayEpisode(TaskPlanner* p) {
  p->ResetEpisode();
  while (!p->episode_done()) p->Complete(p->Available().front(), true, 0.0, {});
}

TEST(TaskPlanner, ExplorationDecaysPerLearnedEpisodeAndTheCountIsSaved) {
  QLearningParams params;
  params.epsilon = 0.3;
  params.epsilon_decay = 0.5;
  params.epsilon_min = 0.05;
  TaskPlanner p(Graph(), params);
  EXPECT_DOUBLE_EQ(p.Epsilon(), 0.3);
  PlayEpisode(&p);
  EXPECT_EQ(p.episodes_learned(), 1u);
  EXPECT_DOUBLE_EQ(p.Epsilon(), 0.15);
  // A failed task does not finish an episode; an unfinished one is not counted.
  p.ResetEpisode();
  p.Complete(0, true, 0.0, {});
  p.Complete(1, false, 0.0, {});
  EXPECT_EQ(p.episodes_learned(), 1u);
  PlayEpisode(&p);
  PlayEpisode(&p);
  EXPECT_EQ(p.episodes_learned(), 3u);
  EXPECT_DOUBLE_EQ(p.Epsilon(), 0.05);  // 0.0375 decayed, held at the floor

  // The count survives a restart, so exploration does not start over.
  const std::string path = TempPath("episodes.bin");
  p.Save(path);
  TaskPlanner q(Graph(), params);
  std::string note;
  ASSERT_TRUE(q.Load(path, &note));
  EXPECT_NE(note.find("3 episodes learned"), std::string::npos) << note;
  EXPECT_EQ(q.episodes_learned(), 3u);
  EXPECT_DOUBLE_EQ(q.Epsilon(), 0.05);

  // Deployment neither explores nor counts.
  QLearningParams deploy = params;
  deploy.learning = false;
  TaskPlanner d(Graph(), deploy);
  ASSERT_TRUE(d.Load(path, &note));
  EXPECT_EQ(d.Epsilon(), 0.0);
  PlayEpisode(&d);
  EXPECT_EQ(d.episodes_learned(), 3u);

  // The default is METHOD 6's constant epsilon.
  TaskPlanner c(Graph(), QLearningParams{});
  PlayEpisode(&c);
  PlayEpisode(&c);
  EXPECT_DOUBLE_EQ(c.Epsilon(), 0.3);
  params.epsilon_decay = 0;
  EXPECT_EQ(params.Validate(), "epsilon_decay must be in (0, 1]");
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".bak");
}

TEST(TaskPlanner, TablesOfEarlierFormatsStillLoad) {
  // Version 3: magic "IPLQTBL3", FNV-1a 64 checksum of the body, then graph
  // hash, task count, row count, episode count, per task the durations
  // observed and their mean, and the rows. Version 2 had no durations,
  // version 1 no episode count either. Made from a version 3 file by
  // dropping those and re-summing.
  const std::string path = TempPath("v1.bin");
  TaskPlanner p(Graph(), QLearningParams{});
  p.Complete(1, true, 0.5, {});
  p.ObserveDuration(1, 2.5);
  PlayEpisode(&p);
  p.Save(path);
  std::string v3;
  {
    std::ifstream in(path, std::ios::binary);
    v3.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  ASSERT_EQ(v3.substr(0, 8), "IPLQTBL3");
  const std::size_t durations = 3 * 16;  // 3 tasks x (count, mean)
  auto write = [&](const std::string& magic, const std::string& body) {
    const uint64_t sum = core::Fnv1a64(body, core::kIplanFnvSeed);
    std::string file = magic;
    file.append(reinterpret_cast<const char*>(&sum), 8);
    file += body;
    std::ofstream(path, std::ios::binary | std::ios::trunc) << file;
    std::filesystem::remove(path + ".bak");
  };
  write("IPLQTBL2", v3.substr(16, 32) + v3.substr(48 + durations));
  TaskPlanner q2(Graph(), QLearningParams{});
  std::string note;
  ASSERT_TRUE(q2.Load(path, &note)) << note;
  EXPECT_NE(note.find("1 episodes learned"), std::string::npos) << note;
  EXPECT_EQ(q2.Q(0, 1), p.Q(0, 1));
  EXPECT_EQ(q2.TaskDuration(1), QLearningParams{}.task_duration_prior);  // none learned in version 2

  write("IPLQTBL1", v3.substr(16, 24) + v3.substr(48 + durations));  // without the episode count at 40..47 too
  TaskPlanner q(Graph(), QLearningParams{});
  ASSERT_TRUE(q.Load(path, &note)) << note;
  EXPECT_NE(note.find("0 episodes learned"), std::string::npos) << note;
  EXPECT_EQ(q.Q(0, 1), p.Q(0, 1));
  EXPECT_NE(q.Q(0, 1), 0.0);
  std::filesystem::remove(path);
}

TEST(TaskPlanner, CorruptTableIsRefusedAndThePreviousGoodOneKept) {
  const std::string path = TempPath("corrupt.bin");
  TaskPlanner p(Graph(), QLearningParams{});
  p.Complete(1, true, 0.5, {});
  p.Save(path);                                   // first good table
  const double q_first = p.Q(0, 1);
  p.ResetEpisode();
  p.Complete(1, true, 0.0, {});
  p.Save(path);                                   // second; the first is now path.bak
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(30);
    f.put('\x7f');                                // damage the newest
  }
  TaskPlanner q(Graph(), QLearningParams{});
  std::string note;
  ASSERT_TRUE(q.Load(path, &note));
  EXPECT_NE(note.find("is corrupt (checksum mismatch); refused it and loaded the previous good table"), std::string::npos)
      << note;
  EXPECT_EQ(q.Q(0, 1), q_first);
  // Both damaged: a clear error.
  std::ofstream(path + ".bak") << "garbage";
  TaskPlanner r(Graph(), QLearningParams{});
  try {
    r.Load(path, &note);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot load the Q-table"), std::string::npos) << e.what();
  }
  // Another graph's table is refused.
  TaskGraph other = Graph();
  other.tasks[1].name = "pick_middle";
  other.tasks[2].after = {"pick_left", "pick_middle"};
  TaskPlanner s(other, QLearningParams{});
  p.Save(path);
  EXPECT_THROW(s.Load(path, &note), std::runtime_error);
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".bak");
}

// Flips one byte of the body, so the checksum no longer matches.
void Damage(const std::string& path) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(30);
  const char c = static_cast<char>(f.get());
  f.seekp(30);
  f.put(static_cast<char>(c ^ 0x5a));
}

// Q(0, 1) of the table in `path` alone (no fallback), or NaN when that file
// does not load.
double LoadedQ01(const std::string& path) {
  const std::string copy = path + ".alone";
  std::filesystem::copy_file(path, copy, std::filesystem::copy_options::overwrite_existing);
  TaskPlanner p(Graph(), QLearningParams{});
  std::string note;
  double q = std::nan("");
  try {
    if (p.Load(copy, &note) && note.rfind("loaded " + copy, 0) == 0) q = p.Q(0, 1);
  } catch (const std::runtime_error&) {
  }
  std::filesystem::remove(copy);
  return q;
}

TEST(TaskPlanner, ARefusedTableNeverReplacesTheGoodBackup) {
  const std::string path = TempPath("rotation.bin");
  TaskPlanner p(Graph(), QLearningParams{});
  p.Complete(1, true, 0.5, {});
  const double q_a = p.Q(0, 1);
  p.Save(path);  // A
  p.ResetEpisode();
  p.Complete(1, true, 0.0, {});
  p.Save(path);  // B; A is now path.bak
  EXPECT_EQ(LoadedQ01(path + ".bak"), q_a);
  Damage(path);

  TaskPlanner q(Graph(), QLearningParams{});
  std::string note;
  ASSERT_TRUE(q.Load(path, &note));
  EXPECT_NE(note.find("refused it and loaded the previous good table"), std::string::npos) << note;
  EXPECT_EQ(q.Q(0, 1), q_a);
  q.ResetEpisode();
  q.Complete(1, true, 2.0, {});
  const double q_c = q.Q(0, 1);
  q.Save(path);  // C over the damaged B: B must not become the backup
  EXPECT_EQ(LoadedQ01(path + ".bak"), q_a);
  EXPECT_EQ(LoadedQ01(path), q_c);

  Damage(path);
  TaskPlanner r(Graph(), QLearningParams{});
  ASSERT_TRUE(r.Load(path, &note)) << note;
  EXPECT_TRUE(r.Q(0, 1) == q_a || r.Q(0, 1) == q_c) << r.Q(0, 1);
  EXPECT_EQ(LoadedQ01(path + ".bak"), q_a);
  // A good main file is rotated as before.
  r.Save(path);  // main damaged: backup still A
  r.Save(path);  // main good: it becomes the backup
  EXPECT_EQ(LoadedQ01(path + ".bak"), r.Q(0, 1));
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".bak");
}

TEST(TaskPlanner, AnAbsurdDelayIsClampedAndANonFiniteOneRefused) {
  QLearningParams params;
  params.delay_weight = 2.0;  // 2 * 1.7e308 overflowed to -inf before the clamp
  TaskPlanner p(Graph(), params);
  const double reward = p.Complete(1, true, 1.7e308, {});
  EXPECT_DOUBLE_EQ(reward, 1.0 - 2.0 * TaskPlanner::kMaxDelay);
  EXPECT_DOUBLE_EQ(p.Q(0, 1), params.alpha * reward);
  EXPECT_EQ(p.Complete(0, true, -5.0, {}), p.Harmony(0, {}));  // a negative delay is no bonus
  EXPECT_EQ(p.refused_outcomes(), 0u);

  // Many absurd episodes with the default weight: Q stays finite and the
  // table saves and reloads (an inf made the supervisor unable to start).
  TaskPlanner d(Graph(), QLearningParams{});
  for (int episode = 0; episode < 200; ++episode) {
    d.ResetEpisode();
    while (!d.episode_done()) d.Complete(d.Available().front(), true, 1.7e308, {});
  }
  for (int t = 0; t < 3; ++t) EXPECT_TRUE(std::isfinite(d.Q(0, t))) << t;
  const std::string path = TempPath("absurd.bin");
  d.Save(path);
  TaskPlanner e(Graph(), QLearningParams{});
  std::string note;
  ASSERT_TRUE(e.Load(path, &note)) << note;
  EXPECT_EQ(note.rfind("loaded " + path, 0), 0u) << note;

  // NaN and inf: nothing learned, but the task did end.
  TaskPlanner n(Graph(), QLearningParams{});
  EXPECT_TRUE(std::isnan(n.Complete(1, true, std::nan(""), {})));
  EXPECT_TRUE(std::isnan(n.Complete(0, true, std::numeric_limits<double>::infinity(), {})));
  EXPECT_EQ(n.Q(0, 1), 0.0);
  EXPECT_EQ(n.Q(2, 0), 0.0);
  EXPECT_EQ(n.state(), 3u);
  EXPECT_EQ(n.refused_outcomes(), 2u);
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".bak");
}

TEST(TaskPlanner, ATableWithANonFiniteValueIsRefusedByName) {
  // A table poisoned by an older planner: the checksum is right, a Q-value is
  // -inf. Layout: magic (8), checksum (8), then the body: graph hash, task
  // count, row count, episodes (8 each), 3 task durations (count and mean,
  // 16 each), rows of state (8) and 3 doubles.
  const std::string path = TempPath("poisoned.bin");
  TaskPlanner p(Graph(), QLearningParams{});
  p.Complete(1, true, 0.5, {});
  p.Save(path);
  p.Save(path);  // a good backup
  std::string data = core::ReadFile(path);
  ASSERT_EQ(data.size(), 48u + 3 * 16 + 8 + 3 * 8);
  const double inf = -std::numeric_limits<double>::infinity();
  std::memcpy(&data[48 + 3 * 16 + 8 + 8], &inf, 8);  // Q(state 0, task 1)
  const uint64_t sum = core::Fnv1a64(data.data() + 16, data.size() - 16, core::kIplanFnvSeed);
  std::memcpy(&data[8], &sum, 8);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << data;

  TaskPlanner q(Graph(), QLearningParams{});
  std::string note;
  ASSERT_TRUE(q.Load(path, &note));
  EXPECT_EQ(note, path + " has a non-finite Q-value (-inf in state 0x0 for task 'pick_right'); refused it and "
                         "loaded the previous good table " + path + ".bak");
  EXPECT_EQ(q.Q(0, 1), p.Q(0, 1));
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".bak");
}

TEST(TaskPlanner, SaveFailuresAreCountedWithTheirReason) {
  TaskPlanner p(Graph(), QLearningParams{});
  EXPECT_EQ(p.save_failures(), 0u);
  EXPECT_EQ(p.last_save_error(), "");
  EXPECT_THROW(p.Save("/nonexistent-dir/q.bin"), std::runtime_error);
  EXPECT_THROW(p.Save("/nonexistent-dir/q.bin"), std::runtime_error);
  EXPECT_EQ(p.save_failures(), 2u);
  EXPECT_NE(p.last_save_error().find("/nonexistent-dir/q.bin"), std::string::npos) << p.last_save_error();
  const std::string path = TempPath("saved.bin");
  p.Save(path);
  EXPECT_EQ(p.save_failures(), 2u);  // a success does not hide that saves failed
  std::filesystem::remove(path);
}

TEST(TaskPlanner, LoadRemovesTheTemporariesOfKilledSaves) {
  const std::string path = TempPath("stale.bin");
  TaskPlanner p(Graph(), QLearningParams{});
  p.Save(path);
  // A pid that is not running: a reaped child.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  const std::string dead = std::to_string(child);
  for (const std::string& f : {path + ".tmp." + dead, path + ".bak.tmp." + dead}) std::ofstream(f) << "half";
  TaskPlanner q(Graph(), QLearningParams{});
  std::string note;
  ASSERT_TRUE(q.Load(path, &note));
  EXPECT_NE(note.find("; removed 2 stale temporary file(s)"), std::string::npos) << note;
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp." + dead));
  EXPECT_FALSE(std::filesystem::exists(path + ".bak.tmp." + dead));
  std::filesystem::remove(path);
}

TEST(SafetyMonitor, StopsUntilEverythingIsSeenNamesCulpritsAndResumes) {
  SafetyMonitor m({"rt/a", "rt/b"});
  bool changed = false;
  SafetyDecision d = m.Evaluate(&changed);
  EXPECT_TRUE(d.stop);
  EXPECT_EQ(d.reason, "rt/a: never seen; rt/b: never seen");
  m.OnData("rt/a");
  m.OnData("rt/b");
  d = m.Evaluate(&changed);
  EXPECT_FALSE(d.stop);
  EXPECT_TRUE(changed);
  m.OnDeadlineMissed("rt/b");
  d = m.Evaluate(&changed);
  EXPECT_TRUE(d.stop);
  EXPECT_EQ(d.reason, "rt/b: deadline missed");
  m.OnLivelinessLost("rt/b", 0);
  EXPECT_EQ(m.Evaluate(&changed).reason, "rt/b: publisher gone (liveliness lost)");
  EXPECT_TRUE(changed);
  m.OnData("rt/b");
  d = m.Evaluate(&changed);
  EXPECT_FALSE(d.stop);
  m.OnRiskVerdict(cell::Verdict::kProtectiveStop, "separation 0.3 m below 0.5 m");
  EXPECT_EQ(m.Evaluate(&changed).reason, "collision risk: separation 0.3 m below 0.5 m");
  m.OnRiskVerdict(cell::Verdict::kSlowDown, "slow");
  EXPECT_FALSE(m.Evaluate(&changed).stop);
  m.Evaluate(&changed);
  EXPECT_FALSE(changed);
}

TEST(SafetyMonitor, ResumesOnlyAfterTheCausesStayedClearForTheResumeDelay) {
  SafetyMonitor m({"rt/a"});
  m.SetResumeDelay(0.5);
  bool changed = false;
  const int64_t s = 1'000'000'000;
  m.OnData("rt/a");
  EXPECT_FALSE(m.Evaluate(&changed, 10 * s).stop);  // a first start needs no delay
  m.OnRiskVerdict(cell::Verdict::kProtectiveStop, "too close");
  EXPECT_TRUE(m.Evaluate(&changed, 11 * s).stop);
  EXPECT_TRUE(changed);
  m.OnRiskVerdict(cell::Verdict::kOk, "");
  SafetyDecision d = m.Evaluate(&changed, 11 * s + s / 10);
  EXPECT_TRUE(d.stop);  // clear for 0 s
  EXPECT_FALSE(changed);
  EXPECT_EQ(d.reason, "collision risk: too close");
  m.OnRiskVerdict(cell::Verdict::kProtectiveStop, "too close again");  // chatter restarts the clock
  EXPECT_TRUE(m.Evaluate(&changed, 11 * s + 3 * s / 10).stop);
  m.OnRiskVerdict(cell::Verdict::kOk, "");
  EXPECT_TRUE(m.Evaluate(&changed, 11 * s + 4 * s / 10).stop);
  EXPECT_TRUE(m.Evaluate(&changed, 11 * s + 8 * s / 10).stop);
  d = m.Evaluate(&changed, 11 * s + 9 * s / 10);
  EXPECT_FALSE(d.stop);
  EXPECT_TRUE(changed);
}

TEST(SafetyMonitor, ARetreatResumesAtOnceAndAStopAfterItWaitsAgain) {
  SafetyMonitor m({"rt/a"});
  m.SetResumeDelay(0.5);
  bool changed = false;
  const int64_t s = 1'000'000'000;
  m.OnData("rt/a");
  EXPECT_FALSE(m.Evaluate(&changed, 10 * s).stop);
  m.OnRiskVerdict(cell::Verdict::kProtectiveStop, "collision bound 1 >= 0.05 in 0.5 s", true);  // a stop is never a retreat
  EXPECT_TRUE(m.Evaluate(&changed, 11 * s).stop);
  // The trajectory now takes the robot out of the person's way: holding it
  // for the delay would keep it where they are coming.
  m.OnRiskVerdict(cell::Verdict::kSlowDown, "retreating from the predicted person", true);
  SafetyDecision d = m.Evaluate(&changed, 11 * s + s / 30);
  EXPECT_FALSE(d.stop) << d.reason;
  EXPECT_TRUE(changed);
  // Stopped again within the delay: the next retreat waits it (no chatter).
  m.OnRiskVerdict(cell::Verdict::kProtectiveStop, "collision bound 1 >= 0.05 in 0.3 s");
  EXPECT_TRUE(m.Evaluate(&changed, 11 * s + 2 * s / 10).stop);
  m.OnRiskVerdict(cell::Verdict::kSlowDown, "retreating from the predicted person", true);
  EXPECT_TRUE(m.Evaluate(&changed, 11 * s + 3 * s / 10).stop);
  EXPECT_TRUE(m.Evaluate(&changed, 11 * s + 7 * s / 10).stop);
  EXPECT_FALSE(m.Evaluate(&changed, 11 * s + 8 * s / 10).stop);
  // Stopped again; a verdict that is clear but no retreat waits the delay.
  m.OnRiskVerdict(cell::Verdict::kProtectiveStop, "too close");
  EXPECT_TRUE(m.Evaluate(&changed, 12 * s).stop);
  m.OnRiskVerdict(cell::Verdict::kOk, "clear");
  EXPECT_TRUE(m.Evaluate(&changed, 12 * s + s / 10).stop);
  EXPECT_FALSE(m.Evaluate(&changed, 12 * s + 7 * s / 10).stop);
  // A retreat does not lift another cause.
  m.OnRiskVerdict(cell::Verdict::kProtectiveStop, "too close");
  EXPECT_TRUE(m.Evaluate(&changed, 13 * s).stop);
  m.OnDeadlineMissed("rt/a");
  m.OnRiskVerdict(cell::Verdict::kSlowDown, "retreating", true);
  d = m.Evaluate(&changed, 13 * s + s / 10);
  EXPECT_TRUE(d.stop);
  EXPECT_EQ(d.reason, "rt/a: deadline missed");
}

TEST(SupervisorSettings, TheDocumentedDefaultsAreTheDeclaredOnesAndValid) {
  const std::string doc = std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md";
  EXPECT_EQ(core::CheckDocumentedDefaults(doc, core::DescribeParams(SupervisorSettings{})), "");
  EXPECT_EQ(SupervisorSettings{}.Validate(), "");
  SupervisorSettings s;
  s.learning.gamma = 1.0;  // the core's [0, 1): the service no longer has a range of its own
  EXPECT_EQ(s.Validate(), "gamma must be in [0, 1)");
  s = SupervisorSettings{};
  s.learning.gamma = 0.9995;
  EXPECT_EQ(s.Validate(), "");
  s.mode = "deployment";
  s.watch.clear();
  EXPECT_NE(s.Validate().find("watch must name at least one topic in deployment"), std::string::npos);
  EXPECT_EQ(core::CheckDocumentedDefaults(doc, core::DescribeParams(TaskGraph{})), "");
}

TEST(TaskGraph, MissingAndUnknownKeysNameTheFileAndTheKey) {
  const std::string path = TempPath("missing.yaml");
  std::ofstream(path) << "robot_tasks:\n  - {name: a, gaol: [0, 1]}\n";
  try {
    LoadTaskGraph(path);
    FAIL() << "a task without a goal was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": task 'a' has no goal (give goal or goal_pose)\n" + path +
                                         ": unknown key 'robot_tasks[0].gaol'");
  }
  std::ofstream(path, std::ios::trunc) << "human_actions: [reach]\n";
  try {
    LoadTaskGraph(path);
    FAIL() << "a graph without tasks was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": key 'robot_tasks': is required but missing");
  }
}

}  // namespace
}  // namespace iplan::supervisor

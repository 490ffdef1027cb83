// `iplan cell-check` on real configuration folders (copies of config/, some
// edited as an integrator would): the shipped cell, whose task graph agrees
// with its person and ISO/TS 15066 monitor, passes; a task declared harmless
// that the monitor would stop, a retreat inside the person's space and a goal
// inside a scene object are found and named; the same cell under undirected
// speeds is not consistent; a broken configuration is refused.
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "test_paths.h"

namespace iplan::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void Write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// Replaces the one match of `pattern` in `file`.
void Edit(const fs::path& file, const std::string& pattern, const std::string& replacement) {
  const std::string text = Read(file);
  const std::regex re(pattern);
  ASSERT_EQ(std::distance(std::sregex_iterator(text.begin(), text.end(), re), std::sregex_iterator()), 1)
      << pattern << " in " << file;
  Write(file, std::regex_replace(text, re, replacement));
}

class CellCheck : public ::testing::Test {
 protected:
  // Runs the check; returns the exit code, output in *out.
  int Run(std::string* out, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> argv = {BinPath("iplan"), "cell-check", "--config-dir", dir_.string(), "--repetitions", "3"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    Process p(argv);
    const auto rc = p.Wait(120s);
    *out = p.Stdout() + p.Stderr();
    return rc.value_or(-1);
  }

  ScratchCell scratch_{"cell-check"};
  const fs::path dir_ = scratch_.config();
};

TEST_F(CellCheck, ShippedCellPassesWithItsMarginTable) {
  std::string out;
  EXPECT_EQ(Run(&out), 0) << out;
  EXPECT_NE(out.find("consistent: every task the graph calls harmless"), std::string::npos) << out;
  // One row per task with a margin per human action and the goal's clearance;
  // declared conflicts are marked and negative (the monitor would stop).
  const std::regex row(R"(fetch_left\s+(-0\.\d\d)\*\s+\+0\.\d\d\s+\+0\.\d\d\s+0\.\d{3})");
  EXPECT_TRUE(std::regex_search(out, row)) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(hand_over\s+\+0\.\d\d\s+-0\.\d\d\*)"))) << out;
  // Where the hand-over withdraws to is clear of every action.
  EXPECT_TRUE(std::regex_search(out, std::regex(R"(hand_over \(retreat\)\s+\+0\.\d\d\s+\+0\.\d\d\s+\+0\.\d\d\s+0\.\d{3})")))
      << out;
}

TEST_F(CellCheck, RetreatInsideThePersonsSpaceIsNamed) {
  // The hand-over "withdraws" to where it handed over: in the assembly.
  Edit(dir_ / "tasks" / "table_top.yaml", R"(retreat: \[[^\]]*\])", "retreat: [-0.274, 0.417, 0.0, -1.68, 0.0, 2.097, 0.8]");
  Edit(dir_ / "tasks" / "table_top.yaml", R"(retreat_pose: \{position: \[[^\]]*\]\})", "retreat_pose: {position: [0.64, -0.18, 0.36]}");
  std::string out;
  EXPECT_EQ(Run(&out), 1) << out;
  EXPECT_NE(out.find("inconsistent: 'hand_over (retreat)': during 'assemble' the person comes within the protective "
                     "separation"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("A retreat must be clear of every action"), std::string::npos) << out;
}

TEST_F(CellCheck, UndirectedSpeedsMakeTheSameCellInconsistent) {
  // The fastest joint and the fastest sphere, whatever their direction, and
  // S_s always: hand_over would be stopped even while the person idles.
  Edit(dir_ / "safety.yaml", R"(directed: true )", "directed: false ");  // the cell's one safety file
  std::string out;
  EXPECT_EQ(Run(&out), 1) << out;
  EXPECT_NE(out.find("inconsistent: 'hand_over' is declared harmless during 'idle'"), std::string::npos) << out;
}

TEST_F(CellCheck, UndeclaredConflictIsNamed) {
  // hand_over no longer declares the assembly it reaches into.
  Edit(dir_ / "tasks" / "table_top.yaml", R"(    conflicts_with: \[assemble\]\n)", "");
  std::string out;
  EXPECT_EQ(Run(&out), 1) << out;
  EXPECT_NE(out.find("inconsistent: 'hand_over' is declared harmless during 'assemble'"), std::string::npos) << out;
  EXPECT_NE(out.find("the monitor would stop the robot there"), std::string::npos) << out;
}

TEST_F(CellCheck, GoalInsideASceneObjectIsNamed) {
  // fetch_left's tool down into the parts bin.
  Edit(dir_ / "tasks" / "table_top.yaml", R"(goal: \[0\.686, 0\.526, 0\.0, -1\.277, 0\.0, 1\.803, 0\.8\])",
       "goal: [0.686, 0.745, 0.0, -1.521, 0.0, 2.266, 0.8]");
  // Given in joints only (a pose there would have no solution clear of the
  // scene: ResolveTaskGoals refuses it, task_goals_test).
  Edit(dir_ / "tasks" / "table_top.yaml", R"(goal_pose: \{position: \[0\.55, 0\.45, 0\.45\]\})", "");
  std::string out;
  EXPECT_EQ(Run(&out), 1) << out;
  EXPECT_NE(out.find("'fetch_left' rests in the static scene"), std::string::npos) << out;
}

TEST_F(CellCheck, UnknownHumanActionAndBrokenConfigAreRefused) {
  Edit(dir_ / "tasks" / "table_top.yaml", R"(human_actions: \[reach_parts, assemble, idle\])",
       "human_actions: [reach_parts, assemble, idle, sweep]");
  std::string out;
  EXPECT_EQ(Run(&out), 1) << out;
  EXPECT_NE(out.find("human action 'sweep' of the task graph is not an action of the synthetic person"),
            std::string::npos)
      << out;
  Write(dir_ / "collision_risk.yaml", "collision_risk: {delta_cl: 2}\n");
  EXPECT_EQ(Run(&out), 2) << out;
  EXPECT_NE(out.find("delta_cl"), std::string::npos) << out;
}

}  // namespace
}  // namespace iplan::testing

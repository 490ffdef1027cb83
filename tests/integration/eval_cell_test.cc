// `iplan eval cell` as a process on a copy of config/ (its intent model
// trained on the first run, as `iplan demo` would): a one-episode run of
// three predictors writes every documented JSON field for every predictor
// and one entry per episode and predictor, the same seed gives the same
// JSON byte for byte, oracle-action tells the task planner the person's
// action and its age, --oracle-error changes the oracles' runs and no
// other, and bad requests are refused with exit code 2 naming the problem.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "iplan/core/atomic_file.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class EvalCell : public ::testing::Test {
 protected:

  int Run(const std::vector<std::string>& extra, std::string* out) {
    std::vector<std::string> argv = {BinPath("iplan"), "eval", "cell", "--config-dir", (dir_ / "config").string(),
                                     "--model-dir", (dir_ / "state").string(), "--quiet"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    Process p(argv);
    const auto rc = p.Wait(300s);
    *out = p.Stdout() + p.Stderr();
    return rc.value_or(-1);
  }

  // `args` followed by `more`.
  static std::vector<std::string> With(std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
  }

  ScratchCell scratch_{"eval-cell"};
  const fs::path dir_ = scratch_.dir();
};

TEST_F(EvalCell, OneEpisodeWritesEveryFieldAndRepeatsForASeed) {
  const std::string a = (dir_ / "a.json").string(), b = (dir_ / "b.json").string();
  const std::vector<std::string> args = {"--episodes", "1", "--seed", "3", "--predictors", "none,model,oracle",
                                         "--episode-limit", "40"};
  std::string out;
  ASSERT_EQ(Run(With(args, {"--json", a}), &out), 0) << out;
  EXPECT_NE(out.find("against none"), std::string::npos) << out;
  EXPECT_NE(out.find("model recovers of the oracle's gain"), std::string::npos) << out;
  ASSERT_EQ(Run(With(args, {"--json", b}), &out), 0) << out;
  const std::string text = core::ReadFile(a);
  EXPECT_EQ(text, core::ReadFile(b)) << "the same seed gave different results";

  const nlohmann::json j = nlohmann::json::parse(text);
  EXPECT_EQ(j["command"], "iplan eval cell");
  EXPECT_EQ(j["num_episodes"], 1);
  for (const std::string name : {"none", "model", "oracle"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(j["predictors"].contains(name));
    const auto& p = j["predictors"][name];
    for (const char* stat : {"median", "p10", "p90"}) {
      EXPECT_TRUE(p["episode_time_s"][stat].is_number()) << stat;
      EXPECT_TRUE(p["robot_idle_s"][stat].is_number()) << stat;
    }
    EXPECT_TRUE(p["robot_idle_s"]["total"].is_number());
    for (const char* count : {"protective_stops", "robot_moving_contacts", "robot_at_rest_contacts", "tasks_done",
                              "tasks_total", "episodes", "episodes_complete"}) {
      EXPECT_TRUE(p[count].is_number_integer()) << count;
    }
    EXPECT_EQ(p["tasks_total"], 5);  // the shipped graph's five tasks
    EXPECT_GT(p["episode_time_s"]["median"].get<double>(), 0.0);
    EXPECT_LE(p["episode_time_s"]["median"].get<double>(), 40.0);
    EXPECT_TRUE(p["vs_none"]["episode_time_median_ratio"].is_number());
  }
  EXPECT_EQ(j["predictors"]["none"]["vs_none"]["episode_time_median_ratio"], 1.0);
  EXPECT_TRUE(j.contains("model_recovers_oracle_gain"));
  ASSERT_EQ(j["people"].size(), 1u);
  EXPECT_FALSE(j["people"][0]["actions"].empty());
  EXPECT_LE(j["people"][0]["actions"][0]["start_s"].get<double>(), 0.0);
  ASSERT_EQ(j["episodes"].size(), 3u);
  for (const auto& e : j["episodes"]) {
    for (const char* key : {"episode", "predictor", "complete", "episode_time_s", "robot_idle_s", "protective_stops",
                            "tasks_done", "robot_moving_contacts", "robot_at_rest_contacts", "tasks"}) {
      EXPECT_TRUE(e.contains(key)) << key << " in " << e.dump();
    }
    ASSERT_FALSE(e["tasks"].empty());
    for (const auto& t : e["tasks"]) {
      for (const char* key : {"task", "person_action", "believed_action", "believed_for_s", "expected_conflict_s",
                              "succeeded", "task_time_s"}) {
        EXPECT_TRUE(t.contains(key)) << key << " in " << t.dump();
      }
    }
  }
  // none gives the task planner nothing to anticipate with; the oracle the truth.
  for (const auto& t : j["episodes"][0]["tasks"]) {
    EXPECT_EQ(t["expected_conflict_s"], 0.0);
    EXPECT_EQ(t["believed_action"], "");
  }
  ASSERT_EQ(j["episodes"][2]["predictor"], "oracle");
  for (const auto& t : j["episodes"][2]["tasks"]) EXPECT_EQ(t["believed_action"], t["person_action"]);
}

TEST_F(EvalCell, OracleActionKnowsTheActionAndTheOracleErrorMovesOnlyTheOracles) {
  const std::string exact = (dir_ / "exact.json").string(), off = (dir_ / "off.json").string();
  const std::vector<std::string> args = {"--episodes", "1", "--seed", "3", "--predictors", "none,oracle,oracle-action",
                                         "--episode-limit", "40"};
  std::string out;
  ASSERT_EQ(Run(With(args, {"--json", exact}), &out), 0) << out;
  ASSERT_EQ(Run(With(args, {"--json", off, "--oracle-error", "0.05"}), &out), 0) << out;
  const nlohmann::json a = nlohmann::json::parse(core::ReadFile(exact)), b = nlohmann::json::parse(core::ReadFile(off));
  EXPECT_EQ(a["oracle_error_std_m"], 0.0);
  EXPECT_EQ(b["oracle_error_std_m"], 0.05);
  ASSERT_TRUE(a["predictors"].contains("oracle-action"));
  ASSERT_EQ(a["episodes"].size(), 3u);
  ASSERT_EQ(a["episodes"][2]["predictor"], "oracle-action");
  for (const auto& t : a["episodes"][2]["tasks"]) {
    EXPECT_EQ(t["believed_action"], t["person_action"]);
    EXPECT_EQ(t["believed_for_s"], t["person_for_s"]);
  }
  // none plans against nothing: its run is the same; the oracles' plans change.
  EXPECT_EQ(a["episodes"][0].dump(), b["episodes"][0].dump());
  for (std::size_t i : {1u, 2u}) {
    SCOPED_TRACE(a["episodes"][i]["predictor"].get<std::string>());
    EXPECT_NE(a["episodes"][i].dump(), b["episodes"][i].dump());
  }
}

TEST_F(EvalCell, BadRequestsAreRefusedWithExitCode2) {
  std::string out;
  EXPECT_EQ(Run({"--predictors", "none,psychic"}, &out), 2) << out;
  EXPECT_NE(out.find("unknown predictor 'psychic'"), std::string::npos) << out;
  EXPECT_EQ(Run({"--episodes", "0"}, &out), 2) << out;
  EXPECT_NE(out.find("--episodes must be at least 1"), std::string::npos) << out;
  // A task graph without the person's graph cannot draw the person.
  const fs::path graph = dir_ / "config" / "tasks" / "table_top.yaml";
  std::string text = core::ReadFile(graph.string());
  text = text.substr(0, text.find("human_graph:")) + text.substr(text.find("rest: home"));
  core::WriteFileAtomically(graph.string(), text);
  EXPECT_EQ(Run({"--episodes", "1"}, &out), 2) << out;
  EXPECT_NE(out.find("no human_graph"), std::string::npos) << out;
}

}  // namespace
}  // namespace iplan::testing

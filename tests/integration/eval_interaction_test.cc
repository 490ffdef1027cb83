// `iplan eval interaction` as a process on a copy of config/ (its intent
// model trained on the first run, as `iplan demo` would): a two-scenario run
// writes every documented JSON field for every predictor and one entry per
// scenario and predictor, the same seed gives the same JSON byte for byte,
// and bad requests are refused with exit code 2 naming the problem.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "iplan/core/atomic_file.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class EvalInteraction : public ::testing::Test {
 protected:

  int Run(const std::vector<std::string>& extra, std::string* out) {
    std::vector<std::string> argv = {BinPath("iplan"),
                                     "eval",
                                     "interaction",
                                     "--config-dir",
                                     (dir_ / "config").string(),
                                     "--recordings",
                                     recordings_,
                                     "--model-dir",
                                     (dir_ / "state").string(),
                                     "--quiet"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    Process p(argv);
    const auto rc = p.Wait(240s);
    *out = p.Stdout() + p.Stderr();
    return rc.value_or(-1);
  }

  ScratchCell scratch_{"eval-interaction"};
  const fs::path dir_ = scratch_.dir();
  std::string recordings_ = std::string(IPLAN_SHARED_DIR) + "/data/assembly.csv";
};

TEST_F(EvalInteraction, TwoScenariosWriteEveryFieldAndRepeatForASeed) {
  const std::string a = (dir_ / "a.json").string(), b = (dir_ / "b.json").string();
  std::string out;
  ASSERT_EQ(Run({"--scenarios", "2", "--seed", "3", "--time-limit", "6", "--json", a}, &out), 0) << out;
  EXPECT_NE(out.find("predictor"), std::string::npos) << out;
  EXPECT_NE(out.find("paired against none"), std::string::npos) << out;
  ASSERT_EQ(Run({"--scenarios", "2", "--seed", "3", "--time-limit", "6", "--json", b}, &out), 0) << out;
  EXPECT_NE(out.find("(cached; trained for this person)"), std::string::npos) << out;
  const std::string text = core::ReadFile(a);
  EXPECT_EQ(text, core::ReadFile(b)) << "the same seed gave different results";

  const nlohmann::json j = nlohmann::json::parse(text);
  const std::vector<std::string> predictors = {"none", "constant-position", "constant-velocity", "model", "oracle"};
  ASSERT_TRUE(j.contains("predictors"));
  for (const auto& name : predictors) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(j["predictors"].contains(name));
    const auto& p = j["predictors"][name];
    for (const char* figure : {"task_time_s", "stop_time_s", "min_separation_m", "max_bound"}) {
      for (const char* stat : {"median", "p10", "p90"}) {
        EXPECT_TRUE(p[figure][stat].is_number()) << figure << "." << stat;
      }
    }
    EXPECT_TRUE(p["protective_stops"]["total"].is_number_integer());
    EXPECT_TRUE(p["protective_stops"]["median"].is_number());
    EXPECT_TRUE(p["true_contacts"].is_number_integer());
    EXPECT_EQ(p["scenarios"], 2);
    EXPECT_GT(p["task_time_s"]["median"].get<double>(), 0.0);
    EXPECT_TRUE(p["vs_none"]["task_time_median_ratio"].is_number());
  }
  EXPECT_EQ(j["predictors"]["none"]["vs_none"]["task_time_median_ratio"], 1.0);
  ASSERT_TRUE(j["scenarios"].is_array());
  ASSERT_EQ(j["scenarios"].size(), 2u * predictors.size());
  for (const auto& s : j["scenarios"]) {
    for (const char* key : {"scenario", "predictor", "source", "subject", "sequence", "placement_m", "delay_s", "task",
                            "start", "goal_q", "task_time_s", "protective_stops", "stop_time_s", "min_separation_m",
                            "max_bound", "true_contacts", "succeeded"}) {
      EXPECT_TRUE(s.contains(key)) << key << " in " << s.dump();
    }
  }
  // The first scenarios are one of each kind of person.
  EXPECT_EQ(j["scenarios"][0]["source"], "recorded");
  EXPECT_EQ(j["scenarios"][0]["task"] != "reach", true);
  EXPECT_EQ(j["scenarios"][predictors.size()]["task"], "reach");
}

TEST_F(EvalInteraction, BadRequestsAreRefusedWithExitCode2) {
  std::string out;
  EXPECT_EQ(Run({"--predictors", "none,psychic", "--scenarios", "2"}, &out), 2) << out;
  EXPECT_NE(out.find("unknown predictor 'psychic'"), std::string::npos) << out;
  // oracle-action continues the person's actions: eval cell's persons only.
  EXPECT_EQ(Run({"--predictors", "none,oracle-action", "--scenarios", "2"}, &out), 2) << out;
  EXPECT_NE(out.find("it runs in iplan eval cell only"), std::string::npos) << out;
  EXPECT_EQ(Run({"--scenarios", "0"}, &out), 2) << out;
  EXPECT_NE(out.find("--scenarios must be at least 1"), std::string::npos) << out;
  recordings_ = (dir_ / "missing.csv").string();
  EXPECT_EQ(Run({"--scenarios", "2"}, &out), 2) << out;
  EXPECT_NE(out.find("missing.csv"), std::string::npos) << out;
}

}  // namespace
}  // namespace iplan::testing

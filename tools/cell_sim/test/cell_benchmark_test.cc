// The episode benchmark's draws and figures on the shipped cell
// (config/): an episode is the same whatever the number of episodes and
// for a seed, its person's actions follow the task graph's human_graph and
// cover the whole run, a setup without the person's graph is refused by
// name, and the summary's ratios and the share of the oracle's gain are
// computed as documented, and oracle-action's future is the episode's
// person until the action ends and that action going on after it. Drawing
// needs no trained intent model (only running does), so the setup carries
// an empty one.
#include "tools/cell_sim/core/cell_benchmark.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "tools/cell_sim/cell_config.h"

namespace iplan::cell_sim {
namespace {

class CellBenchmarkTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { cell_ = new CellConfig(LoadCellConfig(std::string(IPLAN_SOURCE_DIR) + "/config", 1)); }
  static void TearDownTestSuite() { delete cell_; }

  CellBenchmarkSetup Setup() const {
    CellBenchmarkSetup s = cell_->MakeCellSetup();
    s.base.intent_model = std::make_shared<const intent::IntentModel>();
    s.episode_limit = 60;
    return s;
  }

  static CellConfig* cell_;
};

CellConfig* CellBenchmarkTest::cell_ = nullptr;

TEST_F(CellBenchmarkTest, EpisodesAreDrawnFromTheSeedAndTheIndexAlone) {
  const CellBenchmarkSetup setup = Setup();
  ASSERT_EQ(setup.Validate(), "");
  ASSERT_EQ(setup.graph.tasks.size(), 5u);
  const std::vector<EpisodeSpec> few = MakeCellEpisodes(setup, 2, 1), many = MakeCellEpisodes(setup, 6, 1);
  const std::vector<EpisodeSpec> other = MakeCellEpisodes(setup, 2, 2);
  ASSERT_EQ(few.size(), 2u);
  ASSERT_EQ(many.size(), 6u);
  for (std::size_t i = 0; i < few.size(); ++i) {
    EXPECT_EQ(few[i].index, static_cast<int>(i));
    EXPECT_EQ(few[i].noise_seed, many[i].noise_seed);
    EXPECT_EQ(few[i].person_seed, many[i].person_seed);
    ASSERT_EQ(few[i].actions.size(), many[i].actions.size());
    for (std::size_t k = 0; k < few[i].actions.size(); ++k) {
      EXPECT_EQ(few[i].actions[k].action, many[i].actions[k].action);
      EXPECT_EQ(few[i].actions[k].duration, many[i].actions[k].duration);
    }
  }
  EXPECT_NE(few[0].noise_seed, other[0].noise_seed);
  EXPECT_NE(few[0].noise_seed, few[1].noise_seed);
  const double stream = setup.base.loop.task_start + setup.episode_limit + 1.0;  // at least
  for (const EpisodeSpec& e : many) {
    SCOPED_TRACE("episode " + std::to_string(e.index));
    ASSERT_FALSE(e.actions.empty());
    EXPECT_LE(e.actions.front().start, 0.0);       // part way through the first action
    EXPECT_GT(e.actions.front().end(), 0.0);
    EXPECT_GE(e.actions.back().end(), stream);     // the person acts for the whole run
    for (const auto& a : e.actions) {
      const int i = setup.graph.human_graph.Find(a.action);
      ASSERT_GE(i, 0) << a.action;
      const auto& range = setup.graph.human_graph.actions[static_cast<std::size_t>(i)].second.duration;
      EXPECT_GE(a.duration, range[0]);
      EXPECT_LE(a.duration, range[1]);
    }
  }
}

TEST_F(CellBenchmarkTest, ASetupWithoutThePersonsGraphIsRefusedByName) {
  CellBenchmarkSetup setup = Setup();
  setup.graph.human_graph = supervisor::HumanGraph{};
  EXPECT_EQ(setup.Validate(), "the task graph has no human_graph (the person's actions cannot be drawn)");
  EXPECT_THROW(MakeCellEpisodes(setup, 1, 1), std::invalid_argument);
  setup = Setup();
  setup.base.person.script.clear();
  setup.base.person.actions.pop_back();  // the synthetic person cannot idle
  EXPECT_EQ(setup.Validate(), "the synthetic person has no action 'idle' of the human graph");
  setup = Setup();
  EXPECT_THROW(MakeCellEpisodes(setup, 0, 1), std::invalid_argument);
}

TEST_F(CellBenchmarkTest, OracleActionSeesTheEpisodeUntilTheActionEndsAndTheActionGoingOnAfter) {
  const CellBenchmarkSetup setup = Setup();
  const EpisodeSpec e = MakeCellEpisodes(setup, 1, 4)[0];
  const PersonStream person = EpisodePersonStream(setup, e);
  // An `assemble` that ends within the episode and is followed by another action.
  std::size_t span = e.actions.size();
  for (std::size_t i = 0; i + 1 < e.actions.size(); ++i) {
    if (e.actions[i].action == "assemble" && e.actions[i + 1].action != "assemble" && e.actions[i].end() > 1.0 &&
        e.actions[i].end() + 3.0 < setup.episode_limit) {
      span = i;
      break;
    }
  }
  ASSERT_LT(span, e.actions.size()) << "seed 4's episode has no assemble followed by another action";
  const PersonStream continued = ContinuedActionStream(setup, e, span);
  const double end = e.actions[span].end();
  const int last_shared = static_cast<int>(std::floor(end * person.rate_hz));
  ASSERT_GE(continued.num_frames(), last_shared + static_cast<int>(person.rate_hz));
  for (int f = 0; f <= last_shared; ++f) {
    ASSERT_TRUE(continued.truth[static_cast<std::size_t>(f)].isApprox(person.truth[static_cast<std::size_t>(f)], 1e-12))
        << "frame " << f << " (the action ends at " << end << " s)";
  }
  // After the end the person does something else; oracle-action's person
  // goes on assembling, a motion of the action's period.
  const auto it = std::find_if(setup.base.person.actions.begin(), setup.base.person.actions.end(),
                               [](const auto& a) { return a.name == "assemble"; });
  ASSERT_NE(it, setup.base.person.actions.end());
  const double period = it->period;
  Eigen::Matrix3Xd now, later, truth;
  double largest_change = 0;
  // (The stream reaches 1 s of forecast and 1 s beyond the action's end.)
  ASSERT_LT(period, 1.3);
  for (double t = end + 0.1; t < end + 0.7; t += 0.1) {
    continued.TrueAt(t, &now);
    continued.TrueAt(t + period, &later);
    EXPECT_LT((now - later).norm(), 1e-6) << "t " << t;
    person.TrueAt(t, &truth);
    largest_change = std::max(largest_change, (truth - now).colwise().norm().maxCoeff());
  }
  EXPECT_GT(largest_change, 0.05) << "the next action moved no joint 5 cm from where assembling would";
  EXPECT_THROW(ContinuedActionStream(setup, e, e.actions.size()), std::out_of_range);
}

TEST_F(CellBenchmarkTest, TheSummaryPairsEveryPredictorWithNone) {
  auto run = [](Predictor p, double time, double idle, int stops, int done) {
    CellEpisodeResult r;
    r.predictor = p;
    r.episode_time = time;
    r.robot_idle = idle;
    r.protective_stops = stops;
    r.tasks_done = done;
    r.complete = done == 5;
    return r;
  };
  const std::vector<Predictor> predictors = {Predictor::kModel, Predictor::kNone, Predictor::kOracle};
  const std::vector<std::vector<CellEpisodeResult>> results = {
      {run(Predictor::kModel, 18, 1, 0, 5), run(Predictor::kNone, 20, 2, 2, 5), run(Predictor::kOracle, 16, 0.5, 0, 5)},
      {run(Predictor::kModel, 30, 3, 1, 4), run(Predictor::kNone, 24, 4, 3, 5), run(Predictor::kOracle, 20, 1, 0, 5)}};
  const std::vector<CellSummary> s = SummarizeCell(predictors, results, 5);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0].predictor, Predictor::kModel);
  EXPECT_EQ(s[0].episodes, 2);
  EXPECT_EQ(s[0].complete, 1);
  EXPECT_EQ(s[0].tasks_done, 9);
  EXPECT_EQ(s[0].tasks_total, 10);
  EXPECT_EQ(s[0].protective_stops, 1);
  EXPECT_DOUBLE_EQ(s[0].robot_idle_total, 4.0);
  EXPECT_DOUBLE_EQ(s[0].episode_time.median, 18.0);  // nearest rank of {18, 30}
  EXPECT_DOUBLE_EQ(s[1].episode_time.median, 20.0);
  EXPECT_TRUE(s[0].has_reference);
  EXPECT_DOUBLE_EQ(s[0].episode_time_ratio, 18.0 / 20.0);
  EXPECT_DOUBLE_EQ(s[0].robot_idle_ratio, 1.0 / 2.0);
  EXPECT_DOUBLE_EQ(s[0].episode_time_paired_ratio.median, 18.0 / 20.0);  // of {0.9, 1.25}
  EXPECT_DOUBLE_EQ(s[1].episode_time_ratio, 1.0);
  // The model recovers (20 - 18) / (20 - 16) of the oracle's gain; nothing
  // to recover when the oracle gains nothing.
  EXPECT_DOUBLE_EQ(GainRecovered(20, 18, 16), 0.5);
  EXPECT_TRUE(std::isnan(GainRecovered(20, 18, 21)));
}

TEST_F(CellBenchmarkTest, TheSummaryCountsTheChoicesWhoseBeliefWasRight) {
  auto choice = [](const std::string& truth, double truth_for, const std::string& belief, double belief_for) {
    ChosenTask t;
    t.person_action = truth;
    t.person_for = truth_for;
    t.believed_action = belief;
    t.believed_for = belief_for;
    return t;
  };
  CellEpisodeResult model, none;
  model.predictor = Predictor::kModel;
  model.tasks = {choice("reach", 3.0, "reach", 2.5), choice("reach", 3.2, "idle", 0.0), choice("assemble", 1.0, "assemble", 2.0),
                 choice("idle", 0.5, "idle", 0.5)};
  none.predictor = Predictor::kNone;
  none.tasks = {choice("reach", 3.0, "", 0.0)};  // no belief: not a choice told anything
  const std::vector<CellSummary> s = SummarizeCell({Predictor::kModel, Predictor::kNone}, {{model, none}}, 5);
  EXPECT_EQ(s[0].choices_with_belief, 4);
  EXPECT_EQ(s[0].belief_right, 3);
  EXPECT_DOUBLE_EQ(s[0].age_error.median, 0.5);  // nearest rank of {0, 0.5, 1}
  EXPECT_DOUBLE_EQ(s[0].age_error.p90, 1.0);
  EXPECT_EQ(s[1].choices_with_belief, 0);
  EXPECT_EQ(s[1].belief_right, 0);
}

}  // namespace
}  // namespace iplan::cell_sim

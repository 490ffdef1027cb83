// The parts of the evaluation the targets are read from: the hand
// errors at reported horizons between the model's steps, the reaching subset,
// per-frame actions; and training on recordings whose action changes.
#include "iplan/intent/evaluation.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "iplan/intent/kinematic_baseline.h"
#include "iplan/intent/model_io.h"

namespace iplan::intent {
namespace {

// Two joints: a still "head" and a "hand_r" that sweeps back and forth along
// x (period 2 s) in action "sweep", or stays still in action "rest"; with
// `switching`, each recording rests for its first 2 s and then sweeps.
// The hand is flagged reaching while it moves towards +x.
SkeletonDataset Sweeps(unsigned seed, bool switching) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.002);
  SkeletonDataset d;
  d.joint_names = {"head", "hand_r"};
  int id = 0;
  for (const char* subject : {"a", "b", "c"}) {
    for (int a = 0; a < 2; ++a) {
      for (int rep = 0; rep < 3; ++rep) {
        SkeletonSequence s;
        s.id = "sweep" + std::to_string(id++);
        s.subject = subject;
        s.action = a == 0 ? "sweep" : "rest";
        const int n = 90;  // 3 s at 30 Hz
        s.time = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / 30.0);
        s.positions.resize(n, 6);
        s.reaching.resize(n, 2);
        const double phase0 = 0.3 * rep;
        for (int i = 0; i < n; ++i) {
          const double t = s.time(i);
          const bool sweeping = switching ? t >= 2.0 : a == 0;
          const double u = 3.14159265358979 * (t + phase0);
          s.positions.row(i) << 0, 0, 1.7, (sweeping ? 0.3 * std::sin(u) : 0.0), 0.2, 1.2;
          s.reaching(i, 0) = false;
          s.reaching(i, 1) = sweeping && std::cos(u) > 0;
          if (switching) s.frame_actions.push_back(sweeping ? "sweep" : "rest");
        }
        for (int i = 0; i < n; ++i) {
          for (int k = 0; k < 6; ++k) s.positions(i, k) += noise(rng);
        }
        d.sequences.push_back(std::move(s));
      }
    }
  }
  return d;
}

IntentModelConfig SweepConfig() {
  IntentModelConfig c;
  c.joints = DefaultJointConfig({"head", "hand_r"});
  c.rate = 15.0;
  c.window = 8;
  c.horizon = 9;  // 0.6 s
  return c;
}

TrainParams SweepParams() {
  TrainParams p;
  p.sigma_factors = {1.0};
  p.lambdas = {1e-3};
  p.pseudo_inputs = 8;
  p.gp_iterations = 20;
  p.max_forecast_windows = 60;
  return p;
}

TEST(EvaluationTest, HandErrorsAtReportedHorizonsInterpolateBetweenSteps) {
  const SkeletonDataset train = Sweeps(1, false);
  const IntentModel model = TrainIntentModel(train, SweepConfig(), SweepParams());
  ASSERT_EQ(model.config.joints.hands, std::vector<std::string>{"hand_r"});
  const SkeletonDataset test = Sweeps(2, false);
  EvalParams params;
  params.report_horizons = {0.2, 0.5, 1.0};  // 3 steps; 7.5 steps; beyond the horizon (left out)
  const EvalReport r = EvaluateIntentModel(model, test, params);
  ASSERT_EQ(r.hand.joints, std::vector<std::string>{"hand_r"});
  ASSERT_EQ(r.hand.at.size(), 2u);
  EXPECT_EQ(r.hand.num_samples, r.num_forecast_windows);
  // Holding the pose, recomputed from the tracks: at 0.2 s the recorded
  // step 3, at 0.5 s the middle of steps 7 and 8.
  const std::vector<Track> tracks = MakeTracks(test, model.config, 0.6);
  double hold_02 = 0.0, hold_05 = 0.0;
  long n = 0;
  for (const Track& t : tracks) {
    for (int e = 0; e + 9 <= t.positions.rows() - 1; ++e, ++n) {
      const Eigen::RowVector3d now = t.positions.block<1, 3>(e, 3);
      hold_02 += (t.positions.block<1, 3>(e + 3, 3) - now).norm();
      hold_05 += (0.5 * (t.positions.block<1, 3>(e + 7, 3) + t.positions.block<1, 3>(e + 8, 3)) - now).norm();
    }
  }
  ASSERT_EQ(n, r.num_forecast_windows);
  EXPECT_NEAR(r.hand.at[0].horizon_s, 0.2, 1e-12);
  EXPECT_NEAR(r.hand.at[0].const_position, hold_02 / n, 1e-12);
  EXPECT_NEAR(r.hand.at[1].const_position, hold_05 / n, 1e-12);
  // The sweep is smooth and periodic: the model beats both baselines.
  EXPECT_LT(r.hand.at[1].RatioToBestBaseline(), 1.0);
  EXPECT_GT(r.hand.coverage95, 0.0);
  // Reaching: the hand while it moves towards +x, about half of the sweeping windows.
  EXPECT_EQ(r.reaching.joints, std::vector<std::string>{"hand_r"});
  EXPECT_GT(r.reaching.num_samples, r.num_forecast_windows / 5);
  EXPECT_LT(r.reaching.num_samples, r.num_forecast_windows / 2);
  const std::string json = EvalReportToJson(r);
  for (const char* key : {"\"hand\"", "\"reaching\"", "\"ratio_to_best_baseline\"", "\"samples\"", "\"0.5\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " missing in\n" << json;
  }
  // Data without reaching flags report no reaching subset.
  SkeletonDataset plain = test;
  for (SkeletonSequence& s : plain.sequences) s.reaching.resize(0, 0);
  const EvalReport p = EvaluateIntentModel(model, plain, params);
  EXPECT_EQ(p.reaching.num_samples, 0);
  EXPECT_NE(EvalReportToJson(p).find("\"reaching\": null"), std::string::npos);
}

// The sequences are people one after another in one cell: with carry_over
// each starts from the ellipsoid scales the one before ended with, so their
// order matters; without, each starts from the model's and it does not.
TEST(EvaluationTest, CoverageScalesCarryOverFromOneSequenceToTheNext) {
  const IntentModel model = TrainIntentModel(Sweeps(1, false), SweepConfig(), SweepParams());
  const SkeletonDataset test = Sweeps(2, false);
  SkeletonDataset reversed = test;
  std::reverse(reversed.sequences.begin(), reversed.sequences.end());
  EvalParams own;
  own.coverage.carry_over = false;
  const double own_forward = EvaluateIntentModel(model, test, own).coverage95;
  EXPECT_DOUBLE_EQ(EvaluateIntentModel(model, reversed, own).coverage95, own_forward);
  EvalParams carried;
  ASSERT_TRUE(carried.coverage.carry_over);  // the default, as the service's
  const double carried_forward = EvaluateIntentModel(model, test, carried).coverage95;
  EXPECT_NE(carried_forward, own_forward);
  EXPECT_NE(EvaluateIntentModel(model, reversed, carried).coverage95, carried_forward);
  // Carried over, every person but the first starts calibrated: nearer 95 %.
  EXPECT_LT(std::abs(carried_forward - 0.95), std::abs(own_forward - 0.95));
}

// The classifier's cross-validation folds on several threads give the very
// model one thread gives (three subjects: up to three folds at once); a bad
// count is refused.
TEST(TrainingTest, TheModelDoesNotDependOnTheThreadCount) {
  const SkeletonDataset train = Sweeps(1, false);
  TrainParams one = SweepParams();
  one.sigma_factors = {0.5, 1.0};  // a grid, so that the folds run
  one.threads = 1;
  const std::string want = SerializeIntentModel(TrainIntentModel(train, SweepConfig(), one));
  for (const int threads : {2, 3, 0}) {
    TrainParams p = one;
    p.threads = threads;
    EXPECT_EQ(SerializeIntentModel(TrainIntentModel(train, SweepConfig(), p)), want) << threads << " threads";
  }
  one.threads = -1;
  EXPECT_EQ(one.Validate(), "threads -1 must be in [0, 256]");
}

TEST(EvaluationTest, RecordingsWhoseActionChangesTrainAndAreScoredPerFrame) {
  // Rest for 2 s, then sweep: per-frame labels. The classifier learns both
  // actions from them; the accuracy is scored against the action of the
  // frame at the end of each observed prefix (rest before 2 s of 3 s).
  const IntentModel model = TrainIntentModel(Sweeps(3, true), SweepConfig(), SweepParams());
  ASSERT_EQ(model.actions, (std::vector<std::string>{"rest", "sweep"}));
  EvalParams params;
  params.fractions = {0.5, 1.0};
  const EvalReport r = EvaluateIntentModel(model, Sweeps(4, true), params);
  EXPECT_GE(r.accuracy[0], 0.9);  // 1.5 s: resting
  EXPECT_GE(r.accuracy[1], 0.9);  // 3 s: sweeping for 1 s
  EXPECT_EQ(r.confusion.sum(), r.num_sequences);
  EXPECT_GE(r.confusion(1, 1), r.num_sequences * 9 / 10);  // scored as sweeping at the end
  // A frame label the model does not know is refused, naming it.
  SkeletonDataset unknown = Sweeps(4, true);
  unknown.sequences[0].frame_actions[4] = "dance";  // a frame the 15 Hz resampling keeps
  try {
    EvaluateIntentModel(model, unknown, params);
    ADD_FAILURE() << "an unknown frame action must be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("action 'dance'"), std::string::npos) << e.what();
  }
}

TEST(ForecastInputTest, HistorySamplesAreDisplacementsSinceEvenlySpacedRows) {
  JointConfig c;
  c.joints = {"a", "b"};
  c.torso = {"a"};
  const FeatureLayout layout(c);
  // 7 rows: joint a at x = row, joint b at y = 10 * row.
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(7, 6);
  for (int r = 0; r < 7; ++r) {
    w(r, 0) = r;
    w(r, 4) = 10.0 * r;
  }
  EXPECT_EQ(layout.forecast_input_size(2), 6 * 2 + 6 + 3 * 2 * 2);
  const Eigen::VectorXd x = layout.ForecastInput(w, 10.0, 1, 2);
  ASSERT_EQ(x.size(), layout.forecast_input_size(2));
  EXPECT_EQ(x.head(layout.forecast_input_size(0)), layout.ForecastInput(w, 10.0, 1, 0));
  // l = 1: since row 6 - floor(6 / 2) = 3; l = 2: since row 0.
  const Eigen::VectorXd h = x.tail(12);
  EXPECT_EQ(h.segment<3>(0), Eigen::Vector3d(3, 0, 0));
  EXPECT_EQ(h.segment<3>(3), Eigen::Vector3d(0, 30, 0));
  EXPECT_EQ(h.segment<3>(6), Eigen::Vector3d(6, 0, 0));
  EXPECT_EQ(h.segment<3>(9), Eigen::Vector3d(0, 60, 0));
}

TEST(ForecastInputTest, HistorySamplesMustFitTheWindow) {
  IntentModelConfig c = SweepConfig();
  c.history_samples = c.window;
  EXPECT_NE(c.Validate().find("history_samples 8 must be in [0, window - 1 = 7]"), std::string::npos)
      << c.Validate();
}

}  // namespace
}  // namespace iplan::intent

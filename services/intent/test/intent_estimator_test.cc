#include "../core/intent_estimator.h"
#include "../core/intent_settings.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "iplan/core/params.h"

namespace iplan::intent_service {
namespace {

// Small, fast training settings shared by the tests that train a model.
intent::TrainParams SmallTrainParams() {
  intent::TrainParams p;
  p.sigma_factors = {1.0};
  p.lambdas = {1e-3};
  p.pseudo_inputs = 6;
  p.gp_iterations = 15;
  p.max_forecast_windows = 60;
  return p;
}

using intent::IntentModel;
using collision::JointMixture;

const std::vector<std::string> kJoints = {"wrist_l", "wrist_r", "elbow_l", "elbow_r", "shoulder_l", "shoulder_r"};

// Rest pose (3 J), metres, a person 2 m in front of the sensor.
Eigen::VectorXd Rest() {
  return (Eigen::VectorXd(18) << -0.2, -0.4, 2, 0.2, -0.4, 2, -0.2, -0.1, 2, 0.2, -0.1, 2, -0.2, 0.2, 2, 0.2,
          0.2, 2)
      .finished();
}

// Pose of action a (0: raise left wrist, 1: raise right wrist, 2: still) at time t.
Eigen::VectorXd Pose(int a, double t, double speed = 0.6) {
  Eigen::VectorXd p = Rest();
  const double lift = std::min(0.6, speed * t);
  if (a == 0) p(1) += lift;
  if (a == 1) p(4) += lift;
  return p;
}

// A small seeded toy training set: 3 actions x 2 subjects x 3 repetitions at 30 Hz.
intent::SkeletonDataset ToyData() {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.004);
  intent::SkeletonDataset d;
  d.joint_names = kJoints;
  const char* actions[3] = {"raise_left", "raise_right", "still"};
  int id = 0;
  for (const char* subject : {"p1", "p2"}) {
    for (int a = 0; a < 3; ++a) {
      for (int rep = 0; rep < 3; ++rep) {
        intent::SkeletonSequence s;
        s.id = "seq" + std::to_string(id++);
        s.subject = subject;
        s.action = actions[a];
        const int n = 45;
        s.time = Eigen::VectorXd::LinSpaced(n, 0.0, (n - 1) / 30.0);
        s.positions.resize(n, 18);
        for (int i = 0; i < n; ++i) {
          Eigen::VectorXd p = Pose(a, s.time(i), 0.5 + 0.1 * rep);
          for (int k = 0; k < 18; ++k) p(k) += noise(rng);
          s.positions.row(i) = p.transpose();
        }
        d.sequences.push_back(std::move(s));
      }
    }
  }
  return d;
}

SkeletonFrame Frame(std::uint32_t body, double stamp, const Eigen::VectorXd& p,
                    const std::vector<std::string>& names = kJoints) {
  SkeletonFrame f;
  f.body_id = body;
  f.stamp = stamp;
  for (std::size_t j = 0; j < names.size(); ++j) f.joints.push_back({names[j], p.segment<3>(3 * j)});
  return f;
}

class IntentEstimatorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    intent::IntentModelConfig c;
    c.joints = intent::DefaultJointConfig(kJoints);
    c.rate = 15.0;
    c.window = 6;
    c.horizon = 4;
    const intent::TrainParams p = SmallTrainParams();
    IntentModel m = intent::TrainIntentModel(ToyData(), c, p);
    // A fixed accumulating belief filter, so that the tests exercise it
    // whatever the cross-validation picks on the toy data.
    m.classifier.belief = {1.0, 1e-3, true};
    model_ = std::make_shared<const IntentModel>(std::move(m));
  }
  static void TearDownTestSuite() { model_.reset(); }
  static std::shared_ptr<const IntentModel> model_;
};
std::shared_ptr<const IntentModel> IntentEstimatorTest::model_;

// Model joint order may differ from kJoints: reorder a kJoints pose into a model-order row.
Eigen::RowVectorXd ModelRow(const IntentModel& m, const Eigen::VectorXd& p) {
  const auto idx = intent::JointIndices(kJoints, m.config.joints.joints);
  Eigen::RowVectorXd row(3 * idx.size());
  for (std::size_t j = 0; j < idx.size(); ++j) row.segment<3>(3 * j) = p.segment<3>(3 * idx[j]).transpose();
  return row;
}

void ExpectSamePrediction(const JointMixture& a, const JointMixture& b, double tol,
                          bool compare_probabilities = true) {
  ASSERT_EQ(a.actions.size(), b.actions.size());
  for (std::size_t c = 0; c < a.actions.size(); ++c) {
    if (compare_probabilities) {
      EXPECT_NEAR(a.probabilities[c], b.probabilities[c], tol);
    }
    ASSERT_EQ(a.means[c].size(), b.means[c].size());
    for (std::size_t k = 0; k < a.means[c].size(); ++k) {
      EXPECT_LE((a.means[c][k] - b.means[c][k]).norm(), tol);
    }
  }
}

TEST_F(IntentEstimatorTest, FramesAtTheModelRateGiveTheLibraryPredictionOfTheSameWindow) {
  IntentEstimator est(model_, {});
  const int T = model_->config.window;
  const int C = static_cast<int>(model_->actions.size());
  const double dt = 1.0 / model_->config.rate;
  Eigen::MatrixXd rows(0, 18);
  JointMixture got, want;
  // The evaluation's recipe: per-window probabilities through the model's
  // belief filter, fed with the observed (unpadded) last T rows.
  intent::BeliefFilter belief(C, model_->classifier.belief);
  Eigen::VectorXd window_p(C);
  int accumulated = 0;
  for (int i = 0; i < T + 4; ++i) {
    const double t = 1000.0 + i * dt;
    const Eigen::VectorXd p = Pose(1, i * dt);
    ASSERT_TRUE(est.Update(Frame(3, t, p), &got).accepted());
    rows.conservativeResize(rows.rows() + 1, Eigen::NoChange);
    rows.row(rows.rows() - 1) = ModelRow(*model_, p);
    intent::PredictIntent(*model_, rows, &want);  // pads / takes the last T rows itself
    for (int c = 0; c < C; ++c) window_p(c) = want.probabilities[c];
    belief.UpdateWithWindow(window_p, rows.bottomRows(std::min<Eigen::Index>(rows.rows(), T)), T, t);
    accumulated = belief.num_updates();
    for (int c = 0; c < C; ++c) want.probabilities[c] = belief.probabilities()(c);
    ExpectSamePrediction(got, want, 1e-9);
  }
  // The partial window ending at frame T - 2 (the whole history then) and the
  // full windows ending at frames T - 1 ... T + 3.
  EXPECT_EQ(accumulated, 6);
  EXPECT_EQ(got.num_steps, model_->config.horizon);
  EXPECT_EQ(got.num_joints(), 6);
  EXPECT_EQ(model_->actions[got.MostLikely()], "raise_right");
}

TEST_F(IntentEstimatorTest, FasterFramesAreResampledToTheModelRate) {
  // 40 Hz frames of a linear motion: resampling must give exactly the poses
  // at the model-rate grid ending at the newest stamp.
  IntentEstimator est(model_, {});
  const double dt = 1.0 / model_->config.rate;
  const Eigen::VectorXd velocity = Eigen::VectorXd::LinSpaced(18, -0.2, 0.3);
  auto pose = [&](double t) -> Eigen::VectorXd { return Rest() + velocity * t; };
  JointMixture got, want;
  double t = 0;
  for (int i = 0; i < 30; ++i) {
    t = i / 40.0;
    ASSERT_TRUE(est.Update(Frame(1, 50.0 + t, pose(t)), &got).accepted());
  }
  Eigen::MatrixXd grid(model_->config.window, 18);
  for (int r = 0; r < grid.rows(); ++r) grid.row(r) = ModelRow(*model_, pose(t - (grid.rows() - 1 - r) * dt));
  intent::PredictIntent(*model_, grid, &want);
  // Same forecasts; the probabilities are the belief over all windows so far.
  ExpectSamePrediction(got, want, 1e-9, /*compare_probabilities=*/false);
  double sum = 0;
  for (double q : got.probabilities) sum += q;
  EXPECT_NEAR(sum, 1.0, 1e-9);
}

TEST_F(IntentEstimatorTest, ClassifiesARaisedLeftWristFromA30HzStream) {
  IntentEstimator est(model_, {});
  JointMixture got;
  for (int i = 0; i < 40; ++i) ASSERT_TRUE(est.Update(Frame(2, i / 30.0, Pose(0, i / 30.0)), &got).accepted());
  EXPECT_EQ(model_->actions[got.MostLikely()], "raise_left");
  IntentEstimator still(model_, {});
  for (int i = 0; i < 40; ++i) ASSERT_TRUE(still.Update(Frame(2, i / 30.0, Pose(2, i / 30.0)), &got).accepted());
  EXPECT_EQ(model_->actions[got.MostLikely()], "still");
}

TEST_F(IntentEstimatorTest, BadFramesAreRejectedWithAReasonAndChangeNothing) {
  IntentEstimator est(model_, {});
  JointMixture out;
  ASSERT_TRUE(est.Update(Frame(1, 10.0, Rest()), &out).accepted());
  const JointMixture before = out;

  SkeletonFrame missing = Frame(1, 10.1, Rest());
  missing.joints.erase(missing.joints.begin() + 1);  // wrist_r
  FrameResult r = est.Update(missing, &out);
  EXPECT_EQ(r.status, FrameStatus::kMissingJoint);
  EXPECT_NE(r.reason.find("wrist_r"), std::string::npos) << r.reason;

  SkeletonFrame nan = Frame(1, 10.1, Rest());
  nan.joints[3].position.y() = std::numeric_limits<double>::quiet_NaN();
  r = est.Update(nan, &out);
  EXPECT_EQ(r.status, FrameStatus::kMissingJoint);
  EXPECT_NE(r.reason.find("'elbow_r' not detected"), std::string::npos) << r.reason;

  SkeletonFrame zero = Frame(1, 10.1, Rest());
  zero.joints[0].position.setZero();
  EXPECT_EQ(est.Update(zero, &out).status, FrameStatus::kMissingJoint);

  SkeletonFrame dup = Frame(1, 10.1, Rest());
  dup.joints.push_back(dup.joints[2]);
  r = est.Update(dup, &out);
  EXPECT_EQ(r.status, FrameStatus::kDuplicateJoint);
  EXPECT_NE(r.reason.find("elbow_l"), std::string::npos);

  std::vector<std::string> wrong = kJoints;
  for (auto& n : wrong) n = "kinect_" + n;
  r = est.Update(Frame(1, 10.1, Rest(), wrong), &out);
  EXPECT_EQ(r.status, FrameStatus::kMissingJoint);
  EXPECT_NE(r.reason.find("shoulder_l"), std::string::npos) << r.reason;

  SkeletonFrame empty;
  empty.body_id = 1;
  empty.stamp = 10.1;
  EXPECT_EQ(est.Update(empty, &out).status, FrameStatus::kMissingJoint);

  EXPECT_EQ(est.Update(Frame(1, 10.0, Rest()), &out).status, FrameStatus::kStampNotIncreasing);
  EXPECT_EQ(est.Update(Frame(1, 9.0, Rest()), &out).status, FrameStatus::kStampNotIncreasing);
  EXPECT_EQ(est.Update(Frame(1, std::nan(""), Rest()), &out).status, FrameStatus::kStampNotIncreasing);

  EXPECT_EQ(est.buffered_frames(1), 1);
  EXPECT_EQ(est.num_bodies(), 1);
  ExpectSamePrediction(out, before, 0.0);  // output untouched by rejected frames

  // Extra joints the model does not know are ignored; order does not matter.
  SkeletonFrame extra = Frame(1, 10.1, Rest());
  std::swap(extra.joints[0], extra.joints[5]);
  extra.joints.push_back({"knee_l", Eigen::Vector3d(0, -1, 2)});
  EXPECT_TRUE(est.Update(extra, &out).accepted());
  EXPECT_EQ(est.buffered_frames(1), 2);
}

TEST_F(IntentEstimatorTest, BodiesAreIndependentAndForgottenAfterTheTimeout) {
  IntentEstimatorParams p;
  p.body_timeout = 0.5;
  p.max_gap = 0.3;
  p.max_bodies = 2;
  IntentEstimator est(model_, p);
  JointMixture out;
  ASSERT_TRUE(est.Update(Frame(1, 1.0, Rest()), &out).accepted());
  ASSERT_TRUE(est.Update(Frame(2, 0.9, Rest()), &out).accepted());  // own stamp history
  EXPECT_EQ(est.Update(Frame(3, 1.1, Rest()), &out).status, FrameStatus::kTooManyBodies);
  ASSERT_TRUE(est.Update(Frame(1, 1.05, Rest()), &out).accepted());
  EXPECT_EQ(est.buffered_frames(1), 2);
  EXPECT_EQ(est.DropStale(1.3), 0);
  EXPECT_EQ(est.DropStale(1.45), 1);  // body 2 last seen at 0.9
  EXPECT_EQ(est.buffered_frames(2), 0);
  ASSERT_TRUE(est.Update(Frame(3, 1.5, Rest()), &out).accepted());
  // Body 1 comes back after a gap longer than max_gap: its history restarts,
  // and so does its belief (the prediction is that of the single new frame).
  ASSERT_TRUE(est.Update(Frame(1, 1.5, Rest()), &out).accepted());
  EXPECT_EQ(est.buffered_frames(1), 1);
  JointMixture single;
  intent::PredictIntent(*model_, ModelRow(*model_, Rest()), &single);
  ExpectSamePrediction(out, single, 1e-9);
  // A frame of body 3 two timeouts later drops body 1 (not seen since 1.5 s).
  ASSERT_TRUE(est.Update(Frame(3, 2.6, Rest()), &out).accepted());
  EXPECT_EQ(est.num_bodies(), 1);
  EXPECT_EQ(est.buffered_frames(3), 1);
}

// A person who stands still for 10 s narrows their ellipsoids (every matured
// step inside). The next person starts from those scales with
// coverage_carry_over, from the model's without.
TEST_F(IntentEstimatorTest, ANewBodyStartsFromTheScalesLearnedInTheCell) {
  JointMixture first[2];
  for (const bool carry : {false, true}) {
    IntentEstimatorParams p;
    p.coverage_carry_over = carry;
    IntentEstimator est(model_, p);
    JointMixture out;
    for (int i = 0; i < 150; ++i) ASSERT_TRUE(est.Update(Frame(1, i / 15.0, Rest()), &out).accepted());
    ASSERT_TRUE(est.Update(Frame(2, 10.0, Rest()), &first[carry]).accepted());
  }
  JointMixture model_only;
  intent::PredictIntent(*model_, ModelRow(*model_, Rest()), &model_only);
  for (std::size_t c = 0; c < model_only.covariances.size(); ++c) {
    for (std::size_t i = 0; i < model_only.covariances[c].size(); ++i) {
      EXPECT_NEAR(first[0].covariances[c][i].trace(), model_only.covariances[c][i].trace(), 1e-12);
      EXPECT_LT(first[1].covariances[c][i].trace(), 0.5 * model_only.covariances[c][i].trace());
    }
  }
}

TEST_F(IntentEstimatorTest, HistoryIsBoundedByTheWindowSpan) {
  IntentEstimator est(model_, {});
  JointMixture out;
  for (int i = 0; i < 300; ++i) ASSERT_TRUE(est.Update(Frame(1, i / 30.0, Rest()), &out).accepted());
  const double span = (model_->config.window - 1) / model_->config.rate;
  EXPECT_LE(est.buffered_frames(1), static_cast<int>(std::ceil(span * 30)) + 2);
}

// A tracker that gives one wrist only (recorded Florence 3D wrist_r): the
// model has one joint and no torso, the service's skeletons one joint.
TEST(OneJointEstimatorTest, AcceptsOneJointSkeletonsAndRejectsFramesWithoutIt) {
  const intent::SkeletonDataset all = intent::LoadSkeletonCsv(std::string(IPLAN_SHARED_DIR) + "/data/florence3d.csv");
  const int wrist = intent::JointIndices(all.joint_names, {"wrist_r"})[0];
  auto only_wrist = [&](const std::vector<std::string>& subjects) {
    intent::SkeletonDataset d = intent::SelectSubjects(all, subjects);
    for (auto& s : d.sequences) s.positions = Eigen::MatrixXd(s.positions.middleCols(3 * wrist, 3));
    d.joint_names = {"wrist_r"};
    return d;
  };
  intent::IntentModelConfig c;
  intent::JointSelection sel;
  sel.joints = std::vector<std::string>{"wrist_r"};
  sel.torso = std::vector<std::string>{};  // none
  sel.hands = std::vector<std::string>{};
  c.joints = intent::ResolveJointConfig({"wrist_r"}, sel);
  c.rate = 15.0;
  c.window = 6;
  c.horizon = 4;
  const intent::TrainParams p = SmallTrainParams();
  auto model = std::make_shared<const IntentModel>(intent::TrainIntentModel(only_wrist({"s01", "s03"}), c, p));
  IntentEstimator est(model, {});
  ASSERT_EQ(est.joint_names(), std::vector<std::string>{"wrist_r"});

  const intent::SkeletonDataset played = only_wrist({"s02"});
  const intent::SkeletonSequence& seq = played.sequences.at(0);
  JointMixture got;
  for (Eigen::Index i = 0; i < seq.positions.rows(); ++i) {
    SkeletonFrame f;
    f.body_id = 4;
    f.stamp = 100.0 + seq.time(i);
    f.joints.push_back({"wrist_r", seq.positions.row(i).transpose()});
    f.joints.push_back({"wrist_l", Eigen::Vector3d(0.1, 0.2, 2.0)});  // not a model joint: ignored
    const FrameResult r = est.Update(f, &got);
    ASSERT_TRUE(r.accepted()) << r.reason;
    ASSERT_EQ(got.num_joints(), 1);
    ASSERT_EQ(got.num_steps, 4);
    double sum = 0;
    for (int a = 0; a < got.num_actions(); ++a) {
      sum += got.probabilities[a];
      ASSERT_EQ(got.means[a].size(), 4u);
      for (int k = 0; k < 4; ++k) {
        EXPECT_TRUE(got.Mean(a, k, 0).allFinite());
        EXPECT_TRUE(got.Covariance(a, k, 0).allFinite());
      }
    }
    EXPECT_NEAR(sum, 1.0, 1e-9);
  }
  // Forecasts are positions in the skeletons' frame: one step (1/15 s) ahead
  // the wrist is near where it is now.
  const Eigen::Vector3d now = seq.positions.bottomRows(1).transpose();
  for (int a = 0; a < static_cast<int>(got.actions.size()); ++a) EXPECT_LE((got.Mean(a, 0, 0) - now).norm(), 0.3);

  // A skeleton without the model's joint is a counted rejection naming it.
  SkeletonFrame no_wrist;
  no_wrist.body_id = 4;
  no_wrist.stamp = 200.0;
  no_wrist.joints.push_back({"wrist_l", Eigen::Vector3d(0.1, 0.2, 2.0)});
  const FrameResult r = est.Update(no_wrist, &got);
  EXPECT_EQ(r.status, FrameStatus::kMissingJoint);
  EXPECT_NE(r.reason.find("model joints missing from the frame: wrist_r"), std::string::npos) << r.reason;
}

TEST(IntentEstimatorParamsTest, InvalidParamsAreNamed) {
  IntentEstimatorParams p;
  EXPECT_EQ(p.Validate(), "");
  p.body_timeout = 0;
  EXPECT_NE(p.Validate().find("body_timeout"), std::string::npos);
  p = {};
  p.max_bodies = 0;
  EXPECT_NE(p.Validate().find("max_bodies"), std::string::npos);
  EXPECT_THROW(IntentEstimator(nullptr, {}), std::invalid_argument);
}

TEST(IntentSettingsTest, TheDocumentedDefaultsAreTheDeclaredOnesAndTheCellsFileIsValid) {
  EXPECT_EQ(core::CheckDocumentedDefaults(std::string(IPLAN_SOURCE_DIR) + "/docs/configuration.md",
                                          core::DescribeParams(IntentSettings{})),
            "");
  // The cell's own file, read as the service reads it.
  core::ConfigSection file = core::ConfigSection::Load(std::string(IPLAN_SOURCE_DIR) + "/config/intent.yaml");
  IntentSettings s;
  core::ReadParams(file.Section("intent"), &s);
  EXPECT_TRUE(file.Problems().empty()) << file.Problems().front();
  EXPECT_EQ(s.Validate(), "");
  EXPECT_EQ(s.model, "models/cell_intent.model");
  EXPECT_EQ(s.joints.size(), 9u);
  EXPECT_EQ(s.rate_hz, 15.0);
  EXPECT_EQ(s.estimator.max_bodies, 8);
  EXPECT_EQ(s.baseline.covariance, "model");
}

TEST(IntentSettingsTest, BadValuesAreNamed) {
  IntentSettings s;
  s.model = "m.model";
  s.joints = {"wrist_r"};
  s.rate_hz = 15;
  EXPECT_EQ(s.Validate(), "");
  IntentSettings t = s;
  t.rate_hz = 0;
  EXPECT_NE(t.Validate().find("rate_hz"), std::string::npos);
  t = s;
  t.joints.clear();
  EXPECT_NE(t.Validate().find("joints"), std::string::npos);
  t = s;
  t.estimator.max_bodies = 1001;
  EXPECT_NE(t.Validate().find("max_bodies must be in [1, 1000]"), std::string::npos) << t.Validate();
  t = s;
  t.predictor = "oracle";
  EXPECT_NE(t.Validate().find("'oracle'"), std::string::npos);
  t = s;
  t.baseline.covariance = "none";
  EXPECT_NE(t.Validate().find("baseline.covariance"), std::string::npos);
  t = s;
  t.baseline.window = -1;
  EXPECT_NE(t.Validate().find("baseline.window"), std::string::npos) << t.Validate();
  // A missing required key is named by the reader, with the file.
  const std::string path = ::testing::TempDir() + "/intent_missing_model.yaml";
  { std::ofstream(path) << "intent:\n  joints: [a]\n  rate_hz: 15\n"; }
  core::ConfigSection file = core::ConfigSection::Load(path);
  IntentSettings u;
  core::ReadParams(file.Section("intent"), &u);
  ASSERT_FALSE(file.Problems().empty());
  EXPECT_NE(file.Problems().front().find("key 'intent.model': is required but missing"), std::string::npos)
      << file.Problems().front();
}

}  // namespace
}  // namespace iplan::intent_service

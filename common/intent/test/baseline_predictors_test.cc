#include "iplan/intent/baseline_predictors.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

// Two joints moving on straight lines at constant velocity, 30 Hz.
Eigen::VectorXd LinePose(double t) {
  Eigen::VectorXd p(6);
  p << 0.5 + 0.3 * t, -0.2 + 0.1 * t, 1.0 - 0.05 * t,  // joint 0
      1.0, 0.4 - 0.6 * t, 0.2;                         // joint 1
  return p;
}

TEST(BaselinePredictors, ConstantVelocityExtrapolatesAStraightLineExactly) {
  BaselinePredictorParams params;
  params.kind = BaselineKind::kConstantVelocity;
  BaselinePredictor predictor(params, 2);
  JointMixture out;
  double t = 10.0;
  for (int i = 0; i < 12; ++i, t += 1.0 / 30) predictor.Update(t, LinePose(t), &out);
  const double t0 = t - 1.0 / 30;
  ASSERT_EQ(out.actions.size(), 1u);
  EXPECT_EQ(out.actions[0], "constant_velocity");
  EXPECT_DOUBLE_EQ(out.probabilities[0], 1.0);
  EXPECT_EQ(out.num_steps, 15);
  EXPECT_EQ(out.num_joints(), 2);
  EXPECT_NEAR(out.time_step, 1.0 / 15, 1e-15);
  for (int k = 0; k < out.num_steps; ++k) {
    const Eigen::VectorXd truth = LinePose(t0 + (k + 1) * out.time_step);
    for (int j = 0; j < 2; ++j) {
      EXPECT_LT((out.Mean(0, k, j) - truth.segment<3>(3 * j)).norm(), 1e-9) << "step " << k << " joint " << j;
    }
  }
  // Only the fit window (0.25 s at 30 Hz: 8 frames) is kept.
  EXPECT_EQ(predictor.buffered_frames(), 8);
}

TEST(BaselinePredictors, ConstantVelocityCovarianceGrowsAsStated) {
  BaselinePredictorParams params;
  params.kind = BaselineKind::kConstantVelocity;
  params.rate = 10;
  params.horizon = 10;
  params.window = 0.3;
  // Four frames at -0.3, -0.2, -0.1, 0 s: tbar = -0.15, S_tt = 0.05.
  Eigen::VectorXd stamps(4);
  stamps << 0.7, 0.8, 0.9, 1.0;
  Eigen::MatrixXd positions(4, 3);
  for (int i = 0; i < 4; ++i) positions.row(i) = LinePose(stamps(i)).head<3>().transpose();
  JointMixture out;
  PredictBaseline(params, stamps, positions, &out);
  const double sn2 = 1e-4;
  for (int k : {0, 4, 9}) {
    const double t = (k + 1) * 0.1;
    const double accel = 0.5 * 1.0 * t * t;
    const double expected = sn2 + sn2 * (0.25 + (t + 0.15) * (t + 0.15) / 0.05) + accel * accel;
    const Eigen::Matrix3d& c = out.Covariance(0, k, 0);
    EXPECT_NEAR(c(0, 0), expected, 1e-12) << "step " << k;
    EXPECT_NEAR(c(2, 2), expected, 1e-12);
    EXPECT_DOUBLE_EQ(c(0, 1), 0.0);
  }
  EXPECT_GT(out.Covariance(0, 9, 0)(0, 0), out.Covariance(0, 0, 0)(0, 0));
}

TEST(BaselinePredictors, ConstantPositionHoldsTheNewestObservation) {
  BaselinePredictorParams params;
  params.kind = BaselineKind::kConstantPosition;
  BaselinePredictor predictor(params, 2);
  JointMixture out;
  double t = 0.0;
  for (int i = 0; i < 10; ++i, t += 1.0 / 30) predictor.Update(t, LinePose(t), &out);
  const Eigen::VectorXd last = LinePose(t - 1.0 / 30);
  EXPECT_EQ(out.actions[0], "constant_position");
  for (int k = 0; k < out.num_steps; ++k) {
    for (int j = 0; j < 2; ++j) {
      EXPECT_EQ(out.Mean(0, k, j), Eigen::Vector3d(last.segment<3>(3 * j))) << "step " << k;
      const double s = 0.25 * (k + 1) / 15.0;
      EXPECT_NEAR(out.Covariance(0, k, j)(1, 1), 1e-4 + s * s, 1e-15);
    }
  }
}

TEST(BaselinePredictors, ConstantVelocityWithOneFrameHoldsAndIsStillUsable) {
  BaselinePredictorParams params;
  BaselinePredictor predictor(params, 2);
  JointMixture out;
  predictor.Update(3.0, LinePose(3.0), &out);
  EXPECT_EQ(out.Mean(0, 14, 1), Eigen::Vector3d(LinePose(3.0).segment<3>(3)));
  EXPECT_GT(out.Covariance(0, 14, 1)(0, 0), 1e-4);
}

TEST(BaselinePredictors, PerJointGrowthReplacesTheScalar) {
  BaselinePredictorParams params;
  params.kind = BaselineKind::kConstantPosition;
  params.joint_growth = {0.0, 0.5};
  Eigen::VectorXd stamps(1);
  stamps << 2.0;
  Eigen::MatrixXd positions = LinePose(2.0).transpose();
  JointMixture out;
  PredictBaseline(params, stamps, positions, &out);
  const double t = 15 / 15.0;
  EXPECT_NEAR(out.Covariance(0, 14, 0)(0, 0), 1e-4, 1e-15);
  EXPECT_NEAR(out.Covariance(0, 14, 1)(0, 0), 1e-4 + 0.25 * t * t, 1e-15);
  params.joint_growth = {0.1};
  EXPECT_THROW(PredictBaseline(params, stamps, positions, &out), std::invalid_argument);
}

// One joint moving at 0.3 m/s along x, one at rest, 30 Hz for 4 s, no noise.
SkeletonDataset MovingAndStill() {
  SkeletonDataset d;
  d.joint_names = {"hand", "torso"};
  SkeletonSequence s;
  s.id = "line";
  const int n = 120;
  s.time.resize(n);
  s.positions.resize(n, 6);
  for (int i = 0; i < n; ++i) {
    const double t = i / 30.0;
    s.time(i) = t;
    s.positions.row(i) << 0.5 + 0.3 * t, 0.1, 0.2, 1.0, 0.0, 0.3;
  }
  d.sequences.push_back(s);
  return d;
}

TEST(BaselinePredictors, CalibrationFitsEachPredictorsOwnErrors) {
  const SkeletonDataset d = MovingAndStill();
  BaselinePredictorParams cp;
  cp.kind = BaselineKind::kConstantPosition;
  cp.sensor_noise_std = 0;
  // Holding a joint that moves at v errs by v t along one axis: v t / sqrt(3)
  // per coordinate; a joint at rest not at all.
  const std::vector<double> g_cp = CalibrateBaselineGrowth(cp, d, {"hand", "torso"});
  ASSERT_EQ(g_cp.size(), 2u);
  EXPECT_NEAR(g_cp[0], 0.3 / std::sqrt(3.0), 1e-9);
  EXPECT_NEAR(g_cp[1], 0.0, 1e-12);
  // A straight line is what constant velocity predicts exactly.
  BaselinePredictorParams cv = cp;
  cv.kind = BaselineKind::kConstantVelocity;
  const std::vector<double> g_cv = CalibrateBaselineGrowth(cv, d, {"torso", "hand"});
  EXPECT_NEAR(g_cv[0], 0.0, 1e-6);
  EXPECT_NEAR(g_cv[1], 0.0, 1e-6);
  EXPECT_THROW(CalibrateBaselineGrowth(cv, d, {"elbow"}), std::invalid_argument);
}

TEST(BaselinePredictors, RefusesBadInputNamingIt) {
  BaselinePredictorParams bad;
  bad.window = 0;
  EXPECT_THROW(BaselinePredictor(bad, 1), std::invalid_argument);
  BaselinePredictor predictor(BaselinePredictorParams{}, 2);
  JointMixture out;
  predictor.Update(1.0, LinePose(1.0), &out);
  try {
    predictor.Update(1.0, LinePose(1.0), &out);
    FAIL() << "a repeated stamp was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("is not after"), std::string::npos) << e.what();
  }
  EXPECT_EQ(predictor.buffered_frames(), 1);
  EXPECT_THROW(predictor.Update(2.0, Eigen::VectorXd::Zero(5), &out), std::invalid_argument);
  EXPECT_THROW(PredictBaseline(BaselinePredictorParams{}, Eigen::VectorXd(), Eigen::MatrixXd(), &out),
               std::invalid_argument);
}

}  // namespace
}  // namespace iplan::intent

#include "iplan/intent/kinematic_baseline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// n rows of d = 6 columns moving on a straight line at `rate` Hz: column c
// is a_c + b_c t, with t = 0 at the newest row.
Eigen::MatrixXd Line(int n, double rate, Eigen::VectorXd* a, Eigen::VectorXd* b) {
  *a = (Eigen::VectorXd(6) << 0.1, -0.4, 2.0, 0.3, 0.2, 1.8).finished();
  *b = (Eigen::VectorXd(6) << 0.5, 0.0, -0.2, -1.0, 0.05, 0.3).finished();
  Eigen::MatrixXd rows(n, 6);
  for (int i = 0; i < n; ++i) {
    const double t = (i - (n - 1)) / rate;
    rows.row(i) = (*a + t * *b).transpose();
  }
  return rows;
}

TEST(KinematicBaselineTest, ConstantVelocityExtrapolatesALineExactly) {
  Eigen::VectorXd a, b, p, v;
  const double rate = 10.0;
  const Eigen::MatrixXd rows = Line(12, rate, &a, &b);
  for (int L : {2, 3, 5, 12, 40}) {  // 40: clamped to the 12 rows
    SCOPED_TRACE(L);
    FitLine(rows, L, rate, &p, &v);
    EXPECT_LT((p - a).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((v - b).cwiseAbs().maxCoeff(), 1e-12);
    Eigen::MatrixXd out;
    ExtrapolateKinematic(rows, KinematicBaseline{L, kInf}, rate, 7, &out);
    ASSERT_EQ(out.rows(), 7);
    ASSERT_EQ(out.cols(), 6);
    for (int k = 0; k < 7; ++k) {
      const Eigen::VectorXd want = a + ((k + 1) / rate) * b;
      EXPECT_LT((out.row(k).transpose() - want).cwiseAbs().maxCoeff(), 1e-12) << "step " << k;
    }
  }
}

TEST(KinematicBaselineTest, OneFrameHoldsTheNewestRowAndZeroDampingHoldsTheLine) {
  Eigen::VectorXd a, b, p, v;
  const double rate = 15.0;
  Eigen::MatrixXd rows = Line(6, rate, &a, &b);
  rows(5, 0) += 0.03;  // a jump in the newest row
  FitLine(rows, 1, rate, &p, &v);
  EXPECT_EQ(p, rows.row(5).transpose());
  EXPECT_EQ(v, Eigen::VectorXd::Zero(6));
  Eigen::MatrixXd out;
  ExtrapolateKinematic(rows, KinematicBaseline{1, kInf}, rate, 3, &out);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(out.row(k), rows.row(5));
  // tau = 0: every step holds the fitted line's current value.
  FitLine(rows, 4, rate, &p, &v);
  ExtrapolateKinematic(rows, KinematicBaseline{4, 0.0}, rate, 3, &out);
  for (int k = 0; k < 3; ++k) EXPECT_LT((out.row(k).transpose() - p).cwiseAbs().maxCoeff(), 1e-15);
  // A single row: no velocity whatever L is.
  FitLine(rows.bottomRows(1), 5, rate, &p, &v);
  EXPECT_EQ(v, Eigen::VectorXd::Zero(6));
}

TEST(KinematicBaselineTest, DampedVelocityTravelsTauInTheLimit) {
  EXPECT_DOUBLE_EQ(DampedDisplacement(0.7, kInf), 0.7);
  EXPECT_EQ(DampedDisplacement(0.7, 0.0), 0.0);
  EXPECT_NEAR(DampedDisplacement(0.5, 0.5), 0.5 * (1.0 - std::exp(-1.0)), 1e-15);
  EXPECT_NEAR(DampedDisplacement(100.0, 0.3), 0.3, 1e-12);
  // Starts at the fitted velocity: g(t) = t - t^2 / (2 tau) + O(t^3).
  EXPECT_NEAR(DampedDisplacement(1e-6, 0.3), 1e-6 - 1e-12 / 0.6, 1e-17);
  Eigen::VectorXd a, b;
  const Eigen::MatrixXd rows = Line(5, 10.0, &a, &b);
  Eigen::MatrixXd out;
  ExtrapolateKinematic(rows, KinematicBaseline{5, 0.4}, 10.0, 10, &out);
  const Eigen::VectorXd want = a + DampedDisplacement(1.0, 0.4) * b;
  EXPECT_LT((out.row(9).transpose() - want).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(KinematicBaselineTest, LongerFitsAverageOutWhiteNoise) {
  // Seeded white noise on a still point: the fitted position's error falls
  // as the line uses more frames (variance 4/L for large L, vs 1 for L = 1).
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 0.01);
  double err1 = 0.0, err8 = 0.0;
  Eigen::VectorXd p, v;
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::MatrixXd rows(8, 3);
    for (Eigen::Index i = 0; i < rows.size(); ++i) rows.data()[i] = g(rng);
    FitLine(rows, 1, 10.0, &p, &v);
    err1 += p.squaredNorm();
    FitLine(rows, 8, 10.0, &p, &v);
    err8 += p.squaredNorm();
  }
  EXPECT_LT(err8, 0.6 * err1);
}

TEST(KinematicBaselineTest, MeanJointSpeedsArePathLengthPerSecond) {
  // Joint 0 moves 3 cm per frame along x then stops; joint 1 is still.
  Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(5, 6);
  for (int i = 0; i < 5; ++i) rows(i, 0) = 0.03 * std::min(i, 3);
  Eigen::VectorXd u;
  MeanJointSpeeds(rows, 10.0, &u);
  ASSERT_EQ(u.size(), 2);
  EXPECT_NEAR(u(0), 0.09 * 10.0 / 4.0, 1e-12);
  EXPECT_EQ(u(1), 0.0);
  MeanJointSpeeds(rows.topRows(1), 10.0, &u);
  EXPECT_EQ(u, Eigen::VectorXd::Zero(2));
}

TEST(KinematicBaselineTest, InvalidParametersAreNamed) {
  EXPECT_EQ(KinematicBaseline{}.Validate(), "");
  EXPECT_EQ((KinematicBaseline{3, kInf}.Validate()), "");
  EXPECT_NE((KinematicBaseline{0, 1.0}.Validate().find("smoothing_frames 0")), std::string::npos);
  EXPECT_NE((KinematicBaseline{2, -1.0}.Validate().find("damping_time_constant")), std::string::npos);
  EXPECT_NE((KinematicBaseline{2, std::nan("")}.Validate().find("damping_time_constant")),
            std::string::npos);
}

}  // namespace
}  // namespace iplan::intent

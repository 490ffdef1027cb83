#include "iplan/intent/forecast_calibration.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

// N seeded Gaussian errors whose true per-axis variance is true_scale * v + n
// for model variances v drawn from [0.5, 2] x 1e-4 m^2.
void Sample(int N, double true_scale, double noise, unsigned seed, Eigen::MatrixXd* e,
            Eigen::MatrixXd* v) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.5e-4, 2e-4);
  std::normal_distribution<double> g(0.0, 1.0);
  e->resize(N, 3);
  v->resize(N, 3);
  for (int i = 0; i < N; ++i) {
    for (int a = 0; a < 3; ++a) {
      (*v)(i, a) = u(rng);
      (*e)(i, a) = std::sqrt(true_scale * (*v)(i, a) + noise) * g(rng);
    }
  }
}

TEST(ForecastCalibrationTest, CalibratedScaleCoversNinetyFivePercentOfFreshGaussianData) {
  for (double true_scale : {0.2, 1.0, 9.0}) {
    SCOPED_TRACE(true_scale);
    const double noise = 1e-5;
    Eigen::MatrixXd e, v, e2, v2;
    Sample(4000, true_scale, noise, 11, &e, &v);
    // Miscalibrated as given: too wide (0.2), right (1), too narrow (9).
    const double raw = EllipsoidCoverage(e, v, noise, 1.0);
    if (true_scale > 1.0) {
      EXPECT_LT(raw, 0.8);
    }
    if (true_scale < 1.0) {
      EXPECT_GT(raw, 0.99);
    }
    const double s = CalibrateVarianceScale(e, v, noise, 0.95, 1e-4, 1e4);
    EXPECT_NEAR(EllipsoidCoverage(e, v, noise, s), 0.95, 0.002);
    EXPECT_NEAR(s / true_scale, 1.0, 0.15);
    Sample(4000, true_scale, noise, 12, &e2, &v2);  // held-out draw
    EXPECT_NEAR(EllipsoidCoverage(e2, v2, noise, s), 0.95, 0.012);
  }
}

TEST(ForecastCalibrationTest, SensorNoiseAloneCoveringGivesTheLowerBound) {
  Eigen::MatrixXd e, v;
  Sample(1000, 1e-3, 0.0, 5, &e, &v);  // errors far smaller than the noise below
  EXPECT_EQ(CalibrateVarianceScale(e, v, 1e-4, 0.95, 1e-4, 1e4), 1e-4);
  // Exact zero errors (a joint that never moves) are inside even without variance.
  const Eigen::MatrixXd zero = Eigen::MatrixXd::Zero(10, 3);
  EXPECT_EQ(EllipsoidCoverage(zero, zero, 0.0, 1.0), 1.0);
  EXPECT_EQ(CalibrateVarianceScale(zero, zero, 0.0, 0.95, 1e-4, 1e4), 1e-4);
  // Even the largest scale not enough: the upper bound.
  Sample(1000, 1e6, 0.0, 6, &e, &v);
  EXPECT_EQ(CalibrateVarianceScale(e, v, 0.0, 0.95, 1e-4, 1e2), 1e2);
}

TEST(ForecastCalibrationTest, BadArgumentsAreRefused) {
  const Eigen::MatrixXd a = Eigen::MatrixXd::Ones(4, 3), b = Eigen::MatrixXd::Ones(5, 3);
  EXPECT_THROW(CalibrateVarianceScale(a, b, 0.0, 0.95, 1e-4, 1e4), std::invalid_argument);
  EXPECT_THROW(CalibrateVarianceScale(a, a, 0.0, 1.5, 1e-4, 1e4), std::invalid_argument);
  EXPECT_THROW(CalibrateVarianceScale(a, a, 0.0, 0.95, 0.0, 1e4), std::invalid_argument);
  EXPECT_THROW(CalibrateVarianceScale(a, a, 0.0, 0.95, 10.0, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace iplan::intent

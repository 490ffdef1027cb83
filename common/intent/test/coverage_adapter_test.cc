#include "iplan/intent/coverage_adapter.h"

#include <cmath>
#include <random>

#include <Eigen/LU>
#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

// A one-joint, one-action prediction of `horizon` steps: mean at the origin,
// isotropic covariance sigma^2 I.
JointMixture Still(int horizon, double sigma) {
  JointMixture p;
  p.time_step = 0.1;
  p.Resize(1, horizon, 1);
  p.probabilities[0] = 1.0;
  for (int k = 0; k < horizon; ++k) {
    p.means[0][k].setZero();
    p.covariances[0][k] = sigma * sigma * Eigen::Matrix3d::Identity();
  }
  return p;
}

// Runs `seconds` of a person whose true position scatters with std `truth`
// about the predicted mean while the model predicts std `model`; returns the
// share of matured steps inside their (adapted) 95 % ellipsoid over the last
// half and the geometric mean of the variance scale over it.
std::pair<double, double> RunPerson(double truth, double model, double seconds, CoverageAdapterParams params) {
  const int H = 10;
  const double rate = 10.0;
  CoverageAdapter a(1, H, rate, params);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, truth);
  std::vector<std::pair<double, Eigen::Matrix3d>> published;  // stamp, covariance of the first step
  long inside = 0, scored = 0;
  double log_scale = 0.0;
  const int frames = static_cast<int>(seconds * rate);
  for (int f = 0; f < frames; ++f) {
    const double t = f / rate;
    const Eigen::Vector3d x(n(rng), n(rng), n(rng));
    a.Observe(t, x);
    // Score the prediction made one step ago, as published (after Apply).
    if (!published.empty() && f >= frames / 2) {
      const Eigen::Matrix3d& c = published.back().second;
      inside += x.dot(c.inverse() * x) <= 7.815 ? 1 : 0;
      ++scored;
      log_scale += std::log(a.variance_scales()(0));
    }
    JointMixture p = Still(H, model);
    a.Apply(&p);
    a.Record(t, p);
    published.emplace_back(t, p.covariances[0][0]);
  }
  return {static_cast<double>(inside) / std::max<long>(1, scored), std::exp(log_scale / std::max<long>(1, scored))};
}

TEST(CoverageAdapterTest, TooWideEllipsoidsNarrowToTheTargetCoverage) {
  // The model thinks the person scatters 3x more than they do (variance 9x).
  const auto [coverage, scale] = RunPerson(0.01, 0.03, 120.0, CoverageAdapterParams{});
  EXPECT_NEAR(coverage, 0.95, 0.025);
  EXPECT_NEAR(scale, 1.0 / 9.0, 0.04);
}

TEST(CoverageAdapterTest, TooNarrowEllipsoidsWiden) {
  const auto [coverage, scale] = RunPerson(0.02, 0.01, 120.0, CoverageAdapterParams{});
  EXPECT_NEAR(coverage, 0.95, 0.025);
  EXPECT_NEAR(scale, 4.0, 1.5);
}

TEST(CoverageAdapterTest, OffKeepsTheModelsCovariancesAndBoundsHold) {
  CoverageAdapterParams off;
  off.halving_time = 0.0;
  const auto [coverage, scale] = RunPerson(0.01, 0.03, 30.0, off);
  EXPECT_EQ(scale, 1.0);
  EXPECT_GT(coverage, 0.999);
  CoverageAdapterParams bounded;
  bounded.min_scale = 0.5;
  EXPECT_NEAR(RunPerson(0.01, 0.03, 60.0, bounded).second, 0.5, 1e-12);
}

TEST(CoverageAdapterTest, ResetForgetsAndBadInputIsRefused) {
  CoverageAdapter a(1, 4, 10.0);
  for (int f = 0; f < 100; ++f) {
    a.Observe(f / 10.0, Eigen::Vector3d::Zero());
    JointMixture p = Still(4, 1.0);
    a.Apply(&p);
    a.Record(f / 10.0, p);
  }
  EXPECT_LT(a.variance_scales()(0), 0.3);  // always inside for 10 s: narrowed
  a.Reset();
  EXPECT_EQ(a.variance_scales()(0), 1.0);
  EXPECT_THROW(a.Observe(11.0, Eigen::VectorXd::Zero(6)), std::invalid_argument);
  JointMixture wrong = Still(5, 1.0);
  EXPECT_THROW(a.Apply(&wrong), std::invalid_argument);
  EXPECT_THROW(CoverageAdapter(0, 4, 10.0), std::invalid_argument);
  CoverageAdapterParams bad;
  bad.target = 1.0;
  EXPECT_EQ(bad.Validate(), "target 1.000000 must be in (0, 1)");
  EXPECT_THROW(CoverageAdapter(1, 4, 10.0, bad), std::invalid_argument);
}

TEST(CoverageAdapterTest, ResetToScalesStartsANewPersonFromThem) {
  CoverageAdapterParams params;
  params.max_scale = 5.0;
  CoverageAdapter a(2, 4, 10.0, params);
  JointMixture p;
  p.time_step = 0.1;
  p.Resize(1, 4, 2);
  p.probabilities[0] = 1.0;
  for (auto& c : p.covariances[0]) c = Eigen::Matrix3d::Identity();
  a.Record(0.0, p);
  a.Reset(Eigen::Vector2d(3.0, 7.0));  // 7 is past max_scale
  EXPECT_DOUBLE_EQ(a.variance_scales()(0), 3.0);
  EXPECT_DOUBLE_EQ(a.variance_scales()(1), 5.0);
  // The forecast recorded before the reset is not scored: a far-off
  // observation when it matures leaves the scales as they were.
  a.Observe(0.1, Eigen::VectorXd::Constant(6, 100.0));
  EXPECT_DOUBLE_EQ(a.variance_scales()(0), 3.0);
  a.Apply(&p);
  EXPECT_DOUBLE_EQ(p.covariances[0][0](0, 0), 3.0);  // step 0, joint 0
  EXPECT_DOUBLE_EQ(p.covariances[0][1](0, 0), 5.0);  // step 0, joint 1
  EXPECT_THROW(a.Reset(Eigen::Vector3d::Ones()), std::invalid_argument);
}

}  // namespace
}  // namespace iplan::intent

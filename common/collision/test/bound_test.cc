#include "iplan/collision/bound.h"

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace iplan::collision {
namespace {

constexpr double kPi = 3.14159265358979323846;

// One random test case: robot sphere centre b, combined radius R, Gaussian of
// the human sphere centre with covariance eigenvalue ratio up to 1,000.
struct Case {
  Eigen::Vector3d b;
  double R;
  Eigen::Vector3d mu;
  Eigen::Matrix3d sigma;
  int kind;  // 0 inside, 1 near, 2 far
};

Eigen::Matrix3d RandomRotation(std::mt19937_64* rng) {
  std::normal_distribution<double> n01;
  Eigen::Quaterniond q(n01(*rng), n01(*rng), n01(*rng), n01(*rng));
  q.normalize();
  return q.toRotationMatrix();
}

Eigen::Vector3d RandomUnit(std::mt19937_64* rng) {
  std::normal_distribution<double> n01;
  Eigen::Vector3d v(n01(*rng), n01(*rng), n01(*rng));
  return v.normalized();
}

Case RandomCase(std::mt19937_64* rng, int kind) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Case c;
  c.kind = kind;
  c.b = Eigen::Vector3d(u01(*rng) * 2 - 1, u01(*rng) * 2 - 1, u01(*rng));
  c.R = 0.05 + 0.35 * u01(*rng);
  const double sigma_max = 0.02 + 0.28 * u01(*rng);  // m
  const double s_max = sigma_max * sigma_max;
  const double ratio = std::pow(10.0, 3.0 * u01(*rng));  // 1 .. 1000
  const double s_min = s_max / ratio;
  const double s_mid = s_min * std::pow(ratio, u01(*rng));
  const Eigen::Matrix3d V = RandomRotation(rng);
  c.sigma = V * Eigen::Vector3d(s_min, s_mid, s_max).asDiagonal() * V.transpose();
  c.sigma = 0.5 * (c.sigma + c.sigma.transpose()).eval();
  // Distance of the mean beyond the ball in standard deviations along the
  // offset direction (Mahalanobis): near 0..2, far 2..8.
  const Eigen::Vector3d u = RandomUnit(rng);
  const double sigma_dir = 1.0 / std::sqrt(u.dot(c.sigma.inverse() * u));
  double dist = 0.0;
  if (kind == 0) {
    dist = c.R * u01(*rng);
  } else if (kind == 1) {
    dist = c.R * (1.0 + 1e-6) + 2.0 * sigma_dir * u01(*rng);
  } else {
    dist = c.R + sigma_dir * (2.0 + 6.0 * u01(*rng));
  }
  c.mu = c.b + dist * u;
  return c;
}

// Independent density of N(mu, sigma) (Cholesky, not the library's
// eigendecomposition).
struct Density {
  explicit Density(const Case& c) : mu(c.mu), llt(c.sigma) {
    const Eigen::Matrix3d L = llt.matrixL();
    log_norm = -1.5 * std::log(2 * kPi) - std::log(L.diagonal().prod());
    chol = L;
  }
  double LogPdf(const Eigen::Vector3d& x) const {
    const Eigen::Vector3d z = chol.triangularView<Eigen::Lower>().solve(x - mu);
    return log_norm - 0.5 * z.squaredNorm();
  }
  Eigen::Vector3d mu;
  Eigen::LLT<Eigen::Matrix3d> llt;
  Eigen::Matrix3d chol;
  double log_norm;
};

struct Estimate {
  double p;
  double se;
};

// P(||c - b|| <= R) by importance sampling with the uniform distribution on
// the ball as proposal: P = V E_U[f(X)]. Because V f <= V f(x_max) on the
// ball, its variance is at most bound * P / n, so the standard error is
// below bound / sqrt(n) whatever the size of P.
Estimate EstimateUniformBall(const Case& c, int n, std::mt19937_64* rng) {
  const Density f(c);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double V = 4.0 / 3.0 * kPi * c.R * c.R * c.R;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d x = c.b + c.R * std::cbrt(u01(*rng)) * RandomUnit(rng);
    const double w = V * std::exp(f.LogPdf(x));
    sum += w;
    sum2 += w * w;
  }
  const double mean = sum / n;
  const double var = std::max(0.0, sum2 / n - mean * mean);
  return {mean, std::sqrt(var / (n - 1))};
}

// Plain Monte Carlo: fraction of Gaussian samples that fall in the ball.
Estimate EstimateHitCount(const Case& c, int n, std::mt19937_64* rng) {
  const Density f(c);
  std::normal_distribution<double> n01;
  int hits = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d z(n01(*rng), n01(*rng), n01(*rng));
    const Eigen::Vector3d x = c.mu + f.chol * z;
    if ((x - c.b).squaredNorm() <= c.R * c.R) ++hits;
  }
  const double p = static_cast<double>(hits) / n;
  return {p, std::sqrt(std::max(p * (1 - p), 1.0 / n) / n)};
}

FactorizedGaussian Factorize(const Case& c) {
  FactorizedGaussian g;
  EXPECT_TRUE(FactorizeGaussian(c.mu, c.sigma, &g));
  return g;
}

// Soundness against two independent Monte Carlo estimators over 1,200 random
// cases (400 inside, 400 near, 400 far from the ball).
TEST(BoundTest, SoundAgainstMonteCarlo) {
  std::mt19937_64 rng(20240611);
  constexpr int kCasesPerKind = 400;
  constexpr int kUniformSamples = 4000;  // SE <= bound / sqrt(4000) ~ 1.6 %
  int hit_count_checks = 0;
  double worst_relative_se = 0.0;
  for (int kind = 0; kind < 3; ++kind) {
    for (int i = 0; i < kCasesPerKind; ++i) {
      const Case c = RandomCase(&rng, kind);
      const PairBound pb = EvaluatePairBound(Factorize(c), c.b, c.R);
      ASSERT_TRUE(std::isfinite(pb.bound));
      ASSERT_GE(pb.bound, 0.0);
      ASSERT_LE(pb.bound, 1.0);

      const Estimate is = EstimateUniformBall(c, kUniformSamples, &rng);
      if (pb.bound < 0.1) {
        ASSERT_LT(is.se, 0.1 * pb.bound) << "kind " << kind << " case " << i;
        worst_relative_se = std::max(worst_relative_se, is.se / pb.bound);
      }
      EXPECT_GE(pb.bound, is.p - 3.0 * is.se)
          << "kind " << kind << " case " << i << " p=" << is.p << " se=" << is.se;

      // Hit counting needs ~100 / bound samples for SE < 10 % of the bound:
      // affordable for bounds >= 2e-3.
      if (pb.bound >= 2e-3) {
        const int n = std::min(200000, static_cast<int>(std::ceil(150.0 / pb.bound)));
        const Estimate mc = EstimateHitCount(c, n, &rng);
        if (pb.bound < 0.1) {
          ASSERT_LT(mc.se, 0.1 * pb.bound);
        }
        EXPECT_GE(pb.bound, mc.p - 3.0 * mc.se)
            << "kind " << kind << " case " << i << " p=" << mc.p << " se=" << mc.se;
        ++hit_count_checks;
      }
    }
  }
  // The plain estimator must have run on a fair share of the cases.
  EXPECT_GT(hit_count_checks, 300);
  RecordProperty("worst_relative_se", std::to_string(worst_relative_se));
}

// The test above has teeth: the isotropic shortcut of the original prototype
// (x = b + R (mu - b)/||mu - b||) is caught by the same check on strongly
// anisotropic covariances.
TEST(BoundTest, MonteCarloCheckCatchesIsotropicShortcut) {
  std::mt19937_64 rng(7);
  int caught = 0;
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    // Mean beyond the ball along a high-variance axis, offset sideways along
    // the low-variance axis (eigenvalue ratio 100 .. 1000).
    Case c;
    c.b = Eigen::Vector3d::Zero();
    c.R = 0.1 + 0.2 * u01(rng);
    const double s_big = std::pow(0.05 + 0.1 * u01(rng), 2);
    const double s_small = s_big / std::pow(10.0, 2.0 + u01(rng));
    const Eigen::Matrix3d V = RandomRotation(&rng);
    c.sigma = V * Eigen::Vector3d(s_big, s_big, s_small).asDiagonal() * V.transpose();
    c.sigma = 0.5 * (c.sigma + c.sigma.transpose()).eval();
    c.mu = V * Eigen::Vector3d(c.R + (1.0 + 2.0 * u01(rng)) * std::sqrt(s_big), 0.0,
                               c.R * (0.3 + 0.5 * u01(rng)));
    const Density f(c);
    const Eigen::Vector3d x_iso = c.b + c.R * (c.mu - c.b).normalized();
    const double wrong = 4.0 / 3.0 * kPi * std::pow(c.R, 3) * std::exp(f.LogPdf(x_iso));
    if (wrong >= 0.1) continue;
    const Estimate is = EstimateUniformBall(c, 4000, &rng);
    if (wrong < is.p - 3.0 * is.se) ++caught;
  }
  EXPECT_GT(caught, 100);
}

// x_max satisfies the KKT conditions: on the sphere, and the gradient of the
// log-density, Sigma^-1 (mu - x), equals lambda (x - b) with lambda > 0.
TEST(BoundTest, XmaxSatisfiesOptimalityConditions) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 3000; ++i) {
    const Case c = RandomCase(&rng, 1 + i % 2);
    const PairBound pb = EvaluatePairBound(Factorize(c), c.b, c.R);
    ASSERT_GT(pb.lambda, 0.0);
    const Eigen::Vector3d n = pb.x_max - c.b;
    EXPECT_NEAR(n.norm(), c.R, 1e-8 * c.R) << i << " iterations " << pb.iterations;
    const Eigen::Vector3d grad = c.sigma.ldlt().solve(c.mu - pb.x_max);
    EXPECT_LE((grad - pb.lambda * n).norm(), 1e-8 * grad.norm()) << i;
    EXPECT_LE(grad.cross(n).norm(), 1e-8 * grad.norm() * n.norm()) << i;
    EXPECT_GT(grad.dot(n), 0.0) << i;
    // No point of the ball has a higher density: spot-check random points.
    const Density f(c);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const double log_at_max = f.LogPdf(pb.x_max);
    for (int j = 0; j < 20; ++j) {
      const Eigen::Vector3d x = c.b + c.R * std::cbrt(u01(rng)) * RandomUnit(&rng);
      ASSERT_LE(f.LogPdf(x), log_at_max + 1e-9 * std::abs(log_at_max)) << i;
    }
  }
}

TEST(BoundTest, NewtonAgreesWithReferenceBisection) {
  std::mt19937_64 rng(13);
  int newton_iterations_max = 0;
  for (int i = 0; i < 3000; ++i) {
    const Case c = RandomCase(&rng, i % 3);
    const FactorizedGaussian g = Factorize(c);
    const PairBound a = EvaluatePairBound(g, c.b, c.R);
    const PairBound r = EvaluatePairBoundReferenceBisection(g, c.b, c.R);
    EXPECT_LE(std::abs(a.bound - r.bound), 1e-9 * std::max(a.bound, 1e-300)) << i;
    EXPECT_LE(std::abs(a.log_bound - r.log_bound), 1e-9 * std::max(1.0, std::abs(a.log_bound)));
    EXPECT_LE((a.x_max - r.x_max).norm(), 1e-9 * std::max(1.0, a.x_max.norm())) << i;
    EXPECT_LE(std::abs(a.lambda - r.lambda), 1e-9 * std::max(1.0, a.lambda)) << i;
    EXPECT_DOUBLE_EQ(EvaluatePairLogBound(g, c.b, c.R), a.log_bound);
    newton_iterations_max = std::max(newton_iterations_max, a.iterations);
  }
  // Newton from the lower bracket end converges in a handful of steps.
  EXPECT_LE(newton_iterations_max, 10);
}

// The batched kernel gives the scalar results (same arithmetic per lane),
// including a short last batch and means inside the ball.
TEST(BoundTest, BatchedLogBoundsEqualScalar) {
  std::mt19937_64 rng(19);
  for (int trial = 0; trial < 200; ++trial) {
    const Case c = RandomCase(&rng, trial % 3);
    FactorizedGaussian g = Factorize(c);
    const int n = 1 + trial % 11;
    Eigen::Matrix3Xd b(3, n);
    std::vector<double> R(n), out(n, 0.0);
    for (int k = 0; k < n; ++k) {
      const Case other = RandomCase(&rng, k % 3);
      b.col(k) = c.mu + (other.b - other.mu);  // offset distribution of the cases
      R[k] = other.R;
    }
    EvaluatePairLogBounds(g, b, R.data(), out.data());
    std::vector<double> log_volumes(n), out2(n, 0.0);
    for (int k = 0; k < n; ++k) log_volumes[k] = std::log(BallVolume(R[k]));
    EvaluatePairLogBounds(g, b, R.data(), out2.data(), log_volumes.data());
    for (int k = 0; k < n; ++k) {
      const double scalar = EvaluatePairLogBound(g, b.col(k), R[k]);
      EXPECT_NEAR(out[k], scalar, 1e-13 * std::max(1.0, std::abs(scalar))) << trial << " " << k;
      EXPECT_EQ(out2[k], out[k]);
    }
  }
}

// Hand-checked isotropic case: Sigma = s I, ||mu - b|| = D > R gives
// x_max = b + R (mu - b)/D, lambda = (D/R - 1)/s and
// bound = V(R) (2 pi s)^-3/2 exp(-(D - R)^2 / (2 s)).
TEST(BoundTest, IsotropicClosedForm) {
  const double s = 0.01;  // sigma = 0.1 m
  const double R = 0.2;
  const Eigen::Vector3d b(0.3, -0.1, 0.5);
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d mu = b + 0.5 * dir;  // D = 0.5
  FactorizedGaussian g;
  ASSERT_TRUE(FactorizeGaussian(mu, s * Eigen::Matrix3d::Identity(), &g));
  const PairBound pb = EvaluatePairBound(g, b, R);
  EXPECT_NEAR(pb.lambda, (0.5 / 0.2 - 1.0) / 0.01, 1e-10);  // 150
  EXPECT_LE((pb.x_max - (b + 0.2 * dir)).norm(), 1e-14);
  // By hand: V = 4/3 pi 0.008 = 0.0335103, (2 pi 0.01)^-1.5 = 63.4936,
  // exp(-0.09 / 0.02) = exp(-4.5) = 0.0111090 -> 0.0236365.
  EXPECT_NEAR(pb.bound, 0.0236365, 1e-7);
  EXPECT_NEAR(pb.bound,
              4.0 / 3.0 * kPi * std::pow(R, 3) * std::pow(2 * kPi * s, -1.5) *
                  std::exp(-0.09 / (2 * s)),
              1e-15);
}

TEST(BoundTest, MeanInsideBallGivesPeakAndZeroLambda) {
  FactorizedGaussian g;
  const Eigen::Matrix3d sigma = Eigen::Vector3d(0.04, 0.01, 0.0025).asDiagonal();
  const Eigen::Vector3d mu(0.1, 0.0, 0.0);
  ASSERT_TRUE(FactorizeGaussian(mu, sigma, &g));
  const PairBound pb = EvaluatePairBound(g, Eigen::Vector3d::Zero(), 0.15);
  EXPECT_EQ(pb.lambda, 0.0);
  EXPECT_EQ(pb.x_max, mu);
  // peak = (2 pi)^-1.5 (0.04 * 0.01 * 0.0025)^-0.5 = 0.0634936 / 0.001
  const double expected = 4.0 / 3.0 * kPi * std::pow(0.15, 3) * 0.0634936359342410 / 0.001;
  EXPECT_NEAR(pb.bound, std::min(1.0, expected), 1e-12);
  // With a larger ball the bound clamps to 1.
  EXPECT_EQ(EvaluatePairBound(g, Eigen::Vector3d::Zero(), 0.5).bound, 1.0);
  EXPECT_GT(EvaluatePairBound(g, Eigen::Vector3d::Zero(), 0.5).log_bound, 0.0);
}

TEST(BoundTest, FactorizeRejectsBadCovariance) {
  FactorizedGaussian g;
  const Eigen::Vector3d mu = Eigen::Vector3d::Zero();
  EXPECT_FALSE(FactorizeGaussian(mu, Eigen::Vector3d(1, 1, -1).asDiagonal().toDenseMatrix(), &g));
  EXPECT_FALSE(FactorizeGaussian(mu, Eigen::Vector3d(1, 1, 0).asDiagonal().toDenseMatrix(), &g));
  Eigen::Matrix3d nan_sigma = Eigen::Matrix3d::Identity();
  nan_sigma(1, 1) = std::nan("");
  EXPECT_FALSE(FactorizeGaussian(mu, nan_sigma, &g));
  EXPECT_FALSE(FactorizeGaussian(Eigen::Vector3d(0, INFINITY, 0), Eigen::Matrix3d::Identity(), &g));
  EXPECT_TRUE(FactorizeGaussian(mu, 1e-6 * Eigen::Matrix3d::Identity(), &g));
  EXPECT_NEAR(g.log_peak_density, -1.5 * std::log(2 * kPi * 1e-6), 1e-12);
}

}  // namespace
}  // namespace iplan::collision

#include "iplan/intent/ivm.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

Eigen::MatrixXd RbfKernel(const Eigen::MatrixXd& X, double sigma) {
  const Eigen::Index N = X.rows();
  Eigen::MatrixXd K(N, N);
  for (Eigen::Index i = 0; i < N; ++i)
    for (Eigen::Index j = 0; j < N; ++j)
      K(i, j) = std::exp(-(X.row(i) - X.row(j)).squaredNorm() / (2 * sigma * sigma));
  return K;
}

Eigen::VectorXd KernelTo(const Eigen::MatrixXd& X, const IvmModel& m, const Eigen::RowVectorXd& x,
                         double sigma) {
  Eigen::VectorXd k(m.import_index.size());
  for (Eigen::Index s = 0; s < k.size(); ++s)
    k(s) = std::exp(-(X.row(m.import_index(s)) - x).squaredNorm() / (2 * sigma * sigma));
  return k;
}

TEST(IvmTest, RecoversSeparableThreeClassProblem) {
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 0.3);
  const Eigen::MatrixXd centres = (Eigen::MatrixXd(3, 2) << 0, 0, 3, 0, 0, 3).finished();
  const int per_class = 30;
  Eigen::MatrixXd X(3 * per_class, 2);
  std::vector<int> y;
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < per_class; ++i) {
      X.row(c * per_class + i) = centres.row(c) + Eigen::RowVector2d(noise(rng), noise(rng));
      y.push_back(c);
    }
  IvmParams p;
  p.lambda = 1e-3;
  IvmFitSummary summary;
  const IvmModel m = FitIvm(RbfKernel(X, 1.0), y, 3, p, &summary);
  EXPECT_LT(m.import_index.size(), X.rows() / 2) << "import set should be sparse";
  for (size_t k = 1; k < summary.objective.size(); ++k) {
    EXPECT_LE(summary.objective[k], summary.objective[k - 1] + 1e-12);
  }
  // Fresh test points from the same clusters are classified correctly and confidently.
  int correct = 0;
  double min_p = 1.0;
  Eigen::VectorXd prob;
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < 20; ++i) {
      const Eigen::RowVectorXd x = centres.row(c) + Eigen::RowVector2d(noise(rng), noise(rng));
      m.Probabilities(KernelTo(X, m, x, 1.0), &prob);
      EXPECT_NEAR(prob.sum(), 1.0, 1e-12);
      Eigen::Index arg;
      prob.maxCoeff(&arg);
      correct += arg == c;
      min_p = std::min(min_p, prob(c));
    }
  EXPECT_EQ(correct, 60);
  EXPECT_GT(min_p, 0.6);
}

TEST(IvmTest, IndistinguishableClassesGiveNearUniformProbabilities) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  // Every input occurs once with each of the three labels: the classes have
  // identical training distributions, so nothing distinguishes them.
  const int N = 120;
  Eigen::MatrixXd X(N, 2);
  std::vector<int> y;
  for (int i = 0; i < N; ++i) {
    if (i % 3 == 0) X.row(i) = Eigen::RowVector2d(g(rng), g(rng));
    else X.row(i) = X.row(i - i % 3);
    y.push_back(i % 3);
  }
  IvmParams p;
  p.lambda = 1e-4;
  const IvmModel m = FitIvm(RbfKernel(X, 1.0), y, 3, p);
  Eigen::VectorXd prob;
  double worst = 0.0;
  for (int i = 0; i < 50; ++i) {
    const Eigen::RowVectorXd x = Eigen::RowVector2d(g(rng), g(rng));
    m.Probabilities(KernelTo(X, m, x, 1.0), &prob);
    worst = std::max(worst, (prob.array() - 1.0 / 3.0).abs().maxCoeff());
  }
  EXPECT_LT(worst, 0.02);
}

TEST(IvmTest, RejectsBadInput) {
  const Eigen::MatrixXd K = Eigen::MatrixXd::Identity(3, 3);
  EXPECT_THROW(FitIvm(K, {0, 1, 5}, 2, IvmParams{}), std::invalid_argument);
  EXPECT_THROW(FitIvm(K, {0, 1}, 2, IvmParams{}), std::invalid_argument);
  IvmParams bad;
  bad.lambda = -1.0;
  try {
    FitIvm(K, {0, 1, 0}, 2, bad);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lambda"), std::string::npos);
  }
}

TEST(IvmTest, MeanLogLoss) {
  const Eigen::MatrixXd P = (Eigen::MatrixXd(2, 2) << 0.5, 0.5, 0.25, 0.75).finished();
  EXPECT_NEAR(MeanLogLoss(P, {0, 1}), -(std::log(0.5) + std::log(0.75)) / 2, 1e-15);
}

}  // namespace
}  // namespace iplan::intent

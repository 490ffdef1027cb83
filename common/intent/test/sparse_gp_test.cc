#include "iplan/intent/sparse_gp.h"

#include <cmath>
#include <random>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

struct Data {
  Eigen::MatrixXd X, Y;
};

Data MakeData(int N, int D, int P, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Data d{Eigen::MatrixXd(N, D), Eigen::MatrixXd(N, P)};
  for (Eigen::Index i = 0; i < d.X.size(); ++i) d.X.data()[i] = g(rng);
  for (int i = 0; i < N; ++i)
    for (int p = 0; p < P; ++p)
      d.Y(i, p) = std::sin(d.X(i, 0) + p) + 0.5 * d.X(i, D - 1) * (p + 1) + 0.05 * g(rng);
  return d;
}

SparseGpHyper SomeHyper(const Eigen::MatrixXd& U, int D) {
  SparseGpHyper h;
  h.pseudo_inputs = U;
  h.log_lengthscales = Eigen::VectorXd::LinSpaced(D, std::log(0.8), std::log(1.5));
  h.log_signal_variance = std::log(1.3);
  h.log_noise_variance = std::log(0.05);
  return h;
}

// Exact GP with the same kernel, for comparison.
void ExactGp(const Data& d, const SparseGpHyper& h, const Eigen::VectorXd& x, Eigen::VectorXd* mean,
             double* var) {
  const Eigen::Index N = d.X.rows();
  const double sf2 = std::exp(h.log_signal_variance), sn2 = std::exp(h.log_noise_variance);
  const Eigen::ArrayXd il2 = (-2.0 * h.log_lengthscales.array()).exp();
  auto k = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return sf2 * std::exp(-0.5 * ((a - b).array().square() * il2).sum());
  };
  Eigen::MatrixXd K(N, N);
  Eigen::VectorXd ks(N);
  for (Eigen::Index i = 0; i < N; ++i) {
    ks(i) = k(d.X.row(i).transpose(), x);
    for (Eigen::Index j = 0; j < N; ++j) K(i, j) = k(d.X.row(i).transpose(), d.X.row(j).transpose());
  }
  K.diagonal().array() += sn2;
  const Eigen::LLT<Eigen::MatrixXd> llt(K);
  *mean = (llt.solve(d.Y)).transpose() * ks;
  *var = sf2 - ks.dot(llt.solve(ks)) + sn2;
}

TEST(SparseGpTest, PseudoInputsAtTheDataMatchExactGp) {
  const Data d = MakeData(25, 3, 4, 11);
  const SparseGpHyper h = SomeHyper(d.X, 3);  // M = N, U = X
  const SparseGp gp = SparseGp::FromHyper(d.X, d.Y, h, 1e-10);
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int t = 0; t < 10; ++t) {
    const Eigen::Vector3d x(g(rng), g(rng), g(rng));
    Eigen::VectorXd m_sparse, m_exact;
    double v_sparse, v_exact;
    gp.Predict(x, &m_sparse, &v_sparse);
    ExactGp(d, h, x, &m_exact, &v_exact);
    EXPECT_LT((m_sparse - m_exact).cwiseAbs().maxCoeff(), 1e-5);
    EXPECT_NEAR(v_sparse, v_exact, 1e-5);
  }
  // The FITC likelihood equals the exact GP marginal likelihood too.
  const double sn2 = std::exp(h.log_noise_variance), sf2 = std::exp(h.log_signal_variance);
  Eigen::MatrixXd K(25, 25);
  const Eigen::ArrayXd il2 = (-2.0 * h.log_lengthscales.array()).exp();
  for (int i = 0; i < 25; ++i)
    for (int j = 0; j < 25; ++j)
      K(i, j) = sf2 * std::exp(-0.5 * ((d.X.row(i) - d.X.row(j)).array().square() * il2.transpose()).sum());
  K.diagonal().array() += sn2;
  const Eigen::LLT<Eigen::MatrixXd> llt(K);
  const double logdet = 2.0 * Eigen::MatrixXd(llt.matrixL()).diagonal().array().log().sum();
  const double exact = 0.5 * (d.Y.cwiseProduct(llt.solve(d.Y))).sum() + 0.5 * 4 * logdet +
                       0.5 * 25 * 4 * std::log(2 * M_PI);
  EXPECT_NEAR(FitcNegLogLikelihood(d.X, d.Y, h, 1e-10, nullptr), exact, 1e-4 * std::abs(exact));
}

TEST(SparseGpTest, AnalyticGradientMatchesFiniteDifferences) {
  const Data d = MakeData(40, 3, 2, 21);
  std::mt19937 rng(8);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd U(6, 3);
  for (Eigen::Index i = 0; i < U.size(); ++i) U.data()[i] = g(rng);
  const SparseGpHyper h = SomeHyper(U, 3);
  Eigen::VectorXd grad;
  FitcNegLogLikelihood(d.X, d.Y, h, 1e-6, &grad);
  const Eigen::VectorXd theta = PackHyper(h);
  ASSERT_EQ(grad.size(), theta.size());
  for (Eigen::Index i = 0; i < theta.size(); ++i) {
    const double eps = 1e-6;
    Eigen::VectorXd tp = theta, tm = theta;
    tp(i) += eps;
    tm(i) -= eps;
    const double fp = FitcNegLogLikelihood(d.X, d.Y, UnpackHyper(tp, 6, 3), 1e-6, nullptr);
    const double fm = FitcNegLogLikelihood(d.X, d.Y, UnpackHyper(tm, 6, 3), 1e-6, nullptr);
    const double fd = (fp - fm) / (2 * eps);
    EXPECT_NEAR(grad(i), fd, 1e-4 * std::max(1.0, std::abs(fd))) << "parameter " << i;
  }
}

TEST(SparseGpTest, FittingImprovesLikelihoodAndPredictsHeldOutData) {
  const Data train = MakeData(200, 2, 3, 31);
  const Data test = MakeData(50, 2, 3, 32);
  SparseGpParams p;
  p.num_pseudo_inputs = 10;
  p.max_iterations = 0;
  double nll_initial = 0.0, nll_fitted = 0.0;
  SparseGp::Fit(train.X, train.Y, p, &nll_initial);
  p.max_iterations = 100;
  const SparseGp gp = SparseGp::Fit(train.X, train.Y, p, &nll_fitted);
  EXPECT_LT(nll_fitted, nll_initial);
  double se = 0.0, var_sum = 0.0;
  Eigen::VectorXd m;
  double v;
  for (int i = 0; i < test.X.rows(); ++i) {
    gp.Predict(test.X.row(i).transpose(), &m, &v);
    se += (m - test.Y.row(i).transpose()).squaredNorm();
    var_sum += v;
  }
  const double mse = se / (test.X.rows() * 3.0);
  const double y_var = (test.Y.rowwise() - test.Y.colwise().mean()).squaredNorm() / test.Y.size();
  EXPECT_LT(mse, 0.1 * y_var);
  // Predictive variance is of the order of the actual squared error.
  const double mean_var = var_sum / test.X.rows();
  EXPECT_GT(mean_var, 0.2 * mse);
  EXPECT_LT(mean_var, 5.0 * mse + 0.01);
}

}  // namespace
}  // namespace iplan::intent

#include "iplan/intent/sparse_gp.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>

namespace iplan::intent {
namespace {

constexpr double kLog2Pi = 1.8378770664093453;

// Raw SE kernel (without s_f^2): exp(-1/2 sum_d (a_d - b_d)^2 inv_l2_d).
Eigen::MatrixXd RawKernel(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                          const Eigen::VectorXd& inv_l2) {
  const Eigen::MatrixXd As = A * inv_l2.cwiseSqrt().asDiagonal();
  const Eigen::MatrixXd Bs = B * inv_l2.cwiseSqrt().asDiagonal();
  Eigen::MatrixXd D = -2.0 * As * Bs.transpose();
  D.colwise() += As.rowwise().squaredNorm();
  D.rowwise() += Bs.rowwise().squaredNorm().transpose();
  return (-0.5 * D.cwiseMax(0.0)).array().exp().matrix();
}

void CheckSizes(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                const SparseGpHyper& h) {
  if (X.rows() < 1 || X.rows() != Y.rows() || Y.cols() < 1 ||
      h.pseudo_inputs.rows() < 1 || h.pseudo_inputs.cols() != X.cols() ||
      h.log_lengthscales.size() != X.cols()) {
    throw std::invalid_argument(
        "SparseGp: inconsistent sizes: X (" + std::to_string(X.rows()) + " x " +
        std::to_string(X.cols()) + "), Y (" + std::to_string(Y.rows()) + " x " +
        std::to_string(Y.cols()) + "), pseudo-inputs (" +
        std::to_string(h.pseudo_inputs.rows()) + " x " +
        std::to_string(h.pseudo_inputs.cols()) + "), lengthscales (" +
        std::to_string(h.log_lengthscales.size()) + ")");
  }
}

// Shared FITC factorisation.
struct Fitc {
  Eigen::MatrixXd Kmm, Knm;  // with s_f^2 (Kmm with jitter)
  Eigen::LLT<Eigen::MatrixXd> Lm;  // chol(Kmm)
  Eigen::MatrixXd V;         // (M, N) Lm^-1 K_mn
  Eigen::VectorXd lambda;    // (N) diag(K_nn - Q_nn) + s_n^2
  Eigen::LLT<Eigen::MatrixXd> La;  // chol(I + V Lambda^-1 V^T)
  bool ok = false;
};

Fitc Factorise(const Eigen::MatrixXd& X, const SparseGpHyper& h, double jitter) {
  Fitc f;
  const double sf2 = std::exp(h.log_signal_variance);
  const double sn2 = std::exp(h.log_noise_variance);
  const Eigen::VectorXd inv_l2 = (-2.0 * h.log_lengthscales.array()).exp().matrix();
  const Eigen::Index M = h.pseudo_inputs.rows();
  f.Kmm = sf2 * RawKernel(h.pseudo_inputs, h.pseudo_inputs, inv_l2);
  f.Kmm.diagonal().array() += jitter * sf2;
  f.Knm = sf2 * RawKernel(X, h.pseudo_inputs, inv_l2);
  f.Lm.compute(f.Kmm);
  if (f.Lm.info() != Eigen::Success) return f;
  f.V = f.Lm.matrixL().solve(f.Knm.transpose());
  f.lambda = (sf2 - f.V.colwise().squaredNorm().array()).cwiseMax(0.0).matrix().transpose();
  f.lambda.array() += sn2;
  Eigen::MatrixXd Am = f.V * f.lambda.cwiseInverse().asDiagonal() * f.V.transpose();
  Am.diagonal().array() += 1.0;
  f.La.compute(Am);
  f.ok = f.La.info() == Eigen::Success && f.lambda.allFinite() &&
         (f.lambda.array() > 0.0).all();
  (void)M;
  return f;
}

class FitcObjective final : public ceres::FirstOrderFunction {
 public:
  FitcObjective(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y, int M,
                double jitter)
      : X_(X), Y_(Y), M_(M), jitter_(jitter),
        scale_(1.0 / static_cast<double>(X.rows() * Y.cols())) {}

  bool Evaluate(const double* parameters, double* cost,
                double* gradient) const override {
    const int D = static_cast<int>(X_.cols());
    const Eigen::Map<const Eigen::VectorXd> theta(parameters, NumParameters());
    const SparseGpHyper h = UnpackHyper(theta, M_, D);
    Eigen::VectorXd g;
    const double nll =
        FitcNegLogLikelihood(X_, Y_, h, jitter_, gradient != nullptr ? &g : nullptr);
    if (!std::isfinite(nll)) return false;
    *cost = nll * scale_;
    if (gradient != nullptr) {
      Eigen::Map<Eigen::VectorXd>(gradient, NumParameters()) = g * scale_;
    }
    return true;
  }
  int NumParameters() const override {
    return static_cast<int>(M_ * X_.cols() + X_.cols() + 2);
  }

 private:
  const Eigen::MatrixXd& X_;
  const Eigen::MatrixXd& Y_;
  int M_;
  double jitter_;
  double scale_;
};

}  // namespace

std::string SparseGpParams::Validate() const {
  if (num_pseudo_inputs < 1) return "num_pseudo_inputs " + std::to_string(num_pseudo_inputs) + " must be >= 1";
  if (max_iterations < 0) return "max_iterations " + std::to_string(max_iterations) + " must be >= 0";
  if (!(jitter >= 0.0)) return "jitter must be >= 0";
  return "";
}

Eigen::VectorXd PackHyper(const SparseGpHyper& h) {
  const Eigen::Index M = h.pseudo_inputs.rows(), D = h.pseudo_inputs.cols();
  Eigen::VectorXd theta(M * D + D + 2);
  for (Eigen::Index m = 0; m < M; ++m) theta.segment(m * D, D) = h.pseudo_inputs.row(m).transpose();
  theta.segment(M * D, D) = h.log_lengthscales;
  theta(M * D + D) = h.log_signal_variance;
  theta(M * D + D + 1) = h.log_noise_variance;
  return theta;
}

SparseGpHyper UnpackHyper(const Eigen::VectorXd& theta, int M, int D) {
  if (theta.size() != static_cast<Eigen::Index>(M) * D + D + 2) {
    throw std::invalid_argument("UnpackHyper: parameter vector has size " +
                                std::to_string(theta.size()) + ", expected " +
                                std::to_string(M * D + D + 2));
  }
  SparseGpHyper h;
  h.pseudo_inputs.resize(M, D);
  for (int m = 0; m < M; ++m) h.pseudo_inputs.row(m) = theta.segment(m * D, D).transpose();
  h.log_lengthscales = theta.segment(static_cast<Eigen::Index>(M) * D, D);
  h.log_signal_variance = theta(static_cast<Eigen::Index>(M) * D + D);
  h.log_noise_variance = theta(static_cast<Eigen::Index>(M) * D + D + 1);
  return h;
}

double FitcNegLogLikelihood(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                            const SparseGpHyper& h, double jitter,
                            Eigen::VectorXd* gradient) {
  CheckSizes(X, Y, h);
  const Fitc f = Factorise(X, h, jitter);
  if (!f.ok) return std::numeric_limits<double>::infinity();
  const Eigen::Index N = X.rows(), D = X.cols(), M = h.pseudo_inputs.rows();
  const double P = static_cast<double>(Y.cols());
  const double sf2 = std::exp(h.log_signal_variance);
  const double sn2 = std::exp(h.log_noise_variance);
  const Eigen::VectorXd inv_lam = f.lambda.cwiseInverse();

  // C^-1 Y = Lambda^-1 Y - Lambda^-1 V^T A^-1 V Lambda^-1 Y.
  const Eigen::MatrixXd LiY = inv_lam.asDiagonal() * Y;
  const Eigen::MatrixXd VLiY = f.V * LiY;             // (M, P)
  const Eigen::MatrixXd AiVLiY = f.La.solve(VLiY);    // (M, P)
  const Eigen::MatrixXd Yt = LiY - inv_lam.asDiagonal() * (f.V.transpose() * AiVLiY);
  const double quad = (Y.cwiseProduct(Yt)).sum();
  const Eigen::MatrixXd La_L = f.La.matrixL();
  const double logdetA = 2.0 * La_L.diagonal().array().log().sum();
  const double logdetC = logdetA + f.lambda.array().log().sum();
  const double nll = 0.5 * quad + 0.5 * P * logdetC + 0.5 * N * P * kLog2Pi;
  if (gradient == nullptr) return nll;

  // Gm = K_mm^-1 K_mn = Lm^-T V (M, N).
  const Eigen::MatrixXd Gm = f.Lm.matrixU().solve(f.V);
  const Eigen::MatrixXd GmT = Gm.transpose();  // (N, M)
  // C^-1 Gm^T (N, M).
  const Eigen::MatrixXd LiGmT = inv_lam.asDiagonal() * GmT;
  const Eigen::MatrixXd CiGmT =
      LiGmT - inv_lam.asDiagonal() * (f.V.transpose() * f.La.solve(f.V * LiGmT));
  // diag(C^-1)_i = 1/lam_i - (1/lam_i^2) v_i^T A^-1 v_i.
  const Eigen::MatrixXd AiV = f.La.solve(f.V);  // (M, N)
  const Eigen::VectorXd vAv = f.V.cwiseProduct(AiV).colwise().sum().transpose();
  const Eigen::VectorXd diagCi = inv_lam - inv_lam.cwiseProduct(inv_lam).cwiseProduct(vAv);
  // W = P C^-1 - Yt Yt^T; dL = 1/2 tr(W dC).
  const Eigen::VectorXd diagW = P * diagCi - Yt.rowwise().squaredNorm();
  const Eigen::MatrixXd WGmT = P * CiGmT - Yt * (Yt.transpose() * GmT);
  const Eigen::MatrixXd Gnm = WGmT - diagW.asDiagonal() * GmT;  // dL/dK_nm (N, M)
  const Eigen::MatrixXd Gmm = -0.5 * Gm * Gnm;                  // dL/dK_mm (M, M)

  const Eigen::VectorXd inv_l2 = (-2.0 * h.log_lengthscales.array()).exp().matrix();
  const Eigen::MatrixXd& U = h.pseudo_inputs;
  const Eigen::MatrixXd E = Gnm.cwiseProduct(f.Knm);  // (N, M)
  Eigen::MatrixXd Kmm_raw = f.Kmm;
  Kmm_raw.diagonal().array() -= jitter * sf2;
  const Eigen::MatrixXd F = Gmm.cwiseProduct(Kmm_raw);  // (M, M), symmetric
  const Eigen::MatrixXd Fs = 0.5 * (F + F.transpose());

  const Eigen::VectorXd e_col = E.colwise().sum().transpose();  // (M)
  const Eigen::VectorXd e_row = E.rowwise().sum();              // (N)
  const Eigen::MatrixXd EtX = E.transpose() * X;                // (M, D)
  const Eigen::VectorXd f_row = Fs.rowwise().sum();             // (M)
  const Eigen::MatrixXd FU = Fs * U;                            // (M, D)

  gradient->resize(M * D + D + 2);
  Eigen::MatrixXd dU = (EtX - e_col.asDiagonal() * U) + 2.0 * (FU - f_row.asDiagonal() * U);
  dU = dU * inv_l2.asDiagonal();
  for (Eigen::Index m = 0; m < M; ++m) gradient->segment(m * D, D) = dU.row(m).transpose();
  const Eigen::MatrixXd X2 = X.cwiseProduct(X);
  const Eigen::MatrixXd U2 = U.cwiseProduct(U);
  Eigen::VectorXd dlogl =
      (X2.transpose() * e_row) - 2.0 * (EtX.cwiseProduct(U)).colwise().sum().transpose() +
      U2.transpose() * e_col;
  dlogl += 2.0 * (U2.transpose() * f_row) - 2.0 * (U.cwiseProduct(FU)).colwise().sum().transpose();
  gradient->segment(M * D, D) = dlogl.cwiseProduct(inv_l2);
  // s_f^2 scales K_nm, K_mm (jitter included) and diag K_nn.
  (*gradient)(M * D + D) = E.sum() + Gmm.cwiseProduct(f.Kmm).sum() + 0.5 * diagW.sum() * sf2;
  (*gradient)(M * D + D + 1) = 0.5 * diagW.sum() * sn2;
  return nll;
}

void SparseGp::Derive() {
  inv_sq_lengthscales_ = (-2.0 * hyper_.log_lengthscales.array()).exp().matrix();
  signal_variance_ = std::exp(hyper_.log_signal_variance);
  noise_variance_ = std::exp(hyper_.log_noise_variance);
}

SparseGp SparseGp::FromHyper(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                             const SparseGpHyper& hyper, double jitter) {
  CheckSizes(X, Y, hyper);
  const Fitc f = Factorise(X, hyper, jitter);
  if (!f.ok) throw std::runtime_error("SparseGp: FITC matrices are not positive definite");
  SparseGp gp;
  gp.hyper_ = hyper;
  gp.Derive();
  const Eigen::VectorXd inv_lam = f.lambda.cwiseInverse();
  // alpha = Lm^-T A^-1 V Lambda^-1 Y.
  const Eigen::MatrixXd AiVLiY = f.La.solve(f.V * (inv_lam.asDiagonal() * Y));
  gp.alpha_ = f.Lm.matrixU().solve(AiVLiY);
  // K_mm^-1 - B^-1 = Lm^-T (I - A^-1) Lm^-1.
  const Eigen::Index M = hyper.pseudo_inputs.rows();
  Eigen::MatrixXd IminusAi = -f.La.solve(Eigen::MatrixXd::Identity(M, M));
  IminusAi.diagonal().array() += 1.0;
  const Eigen::MatrixXd T1 = f.Lm.matrixU().solve(IminusAi);           // Lm^-T (I - A^-1)
  gp.cov_correction_ = f.Lm.matrixU().solve(T1.transpose()).transpose();  // ... Lm^-1
  gp.cov_correction_ = 0.5 * (gp.cov_correction_ + gp.cov_correction_.transpose()).eval();
  return gp;
}

SparseGp SparseGp::Fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                       const SparseGpParams& params, double* final_nll) {
  const std::string error = params.Validate();
  if (!error.empty()) throw std::invalid_argument("SparseGpParams: " + error);
  if (X.rows() < 2 || X.rows() != Y.rows() || Y.cols() < 1 || X.cols() < 1) {
    throw std::invalid_argument("SparseGp::Fit: need N >= 2 rows in X (" +
                                std::to_string(X.rows()) + ") and Y (" +
                                std::to_string(Y.rows()) + ")");
  }
  const int N = static_cast<int>(X.rows());
  const int D = static_cast<int>(X.cols());
  const int M = std::min(params.num_pseudo_inputs, N);
  std::mt19937_64 rng(params.seed);
  std::vector<int> order(N);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  SparseGpHyper h;
  h.pseudo_inputs.resize(M, D);
  for (int m = 0; m < M; ++m) h.pseudo_inputs.row(m) = X.row(order[m]);
  const Eigen::RowVectorXd mean = X.colwise().mean();
  const Eigen::VectorXd sd =
      ((X.rowwise() - mean).colwise().squaredNorm() / N).cwiseSqrt().transpose();
  h.log_lengthscales = (sd.array().max(1e-3) * std::sqrt(static_cast<double>(D))).log().matrix();
  const double yvar = std::max(
      1e-12, (Y.rowwise() - Y.colwise().mean()).squaredNorm() / (static_cast<double>(N) * Y.cols()));
  h.log_signal_variance = std::log(yvar);
  h.log_noise_variance = std::log(0.1 * yvar);

  if (params.max_iterations > 0) {
    Eigen::VectorXd theta = PackHyper(h);
    ceres::GradientProblem problem(new FitcObjective(X, Y, M, params.jitter));
    ceres::GradientProblemSolver::Options options;
    options.line_search_direction_type = ceres::LBFGS;
    options.max_num_iterations = params.max_iterations;
    options.logging_type = ceres::SILENT;
    options.minimizer_progress_to_stdout = false;
    options.function_tolerance = 1e-9;
    options.gradient_tolerance = 1e-8;
    ceres::GradientProblemSolver::Summary summary;
    ceres::Solve(options, problem, theta.data(), &summary);
    h = UnpackHyper(theta, M, D);
  }
  if (final_nll != nullptr) *final_nll = FitcNegLogLikelihood(X, Y, h, params.jitter, nullptr);
  return FromHyper(X, Y, h, params.jitter);
}

SparseGp SparseGp::FromParts(SparseGpHyper hyper, Eigen::MatrixXd alpha,
                             Eigen::MatrixXd cov_correction) {
  const Eigen::Index M = hyper.pseudo_inputs.rows();
  if (M < 1 || hyper.log_lengthscales.size() != hyper.pseudo_inputs.cols() ||
      alpha.rows() != M || alpha.cols() < 1 || cov_correction.rows() != M ||
      cov_correction.cols() != M) {
    throw std::invalid_argument("SparseGp::FromParts: inconsistent sizes (M = " +
                                std::to_string(M) + ")");
  }
  SparseGp gp;
  gp.hyper_ = std::move(hyper);
  gp.alpha_ = std::move(alpha);
  gp.cov_correction_ = std::move(cov_correction);
  gp.Derive();
  return gp;
}

void SparseGp::Predict(const Eigen::Ref<const Eigen::VectorXd>& x,
                       Eigen::VectorXd* mean, double* variance) const {
  const Eigen::MatrixXd& U = hyper_.pseudo_inputs;
  const Eigen::Index M = U.rows();
  Eigen::VectorXd k(M);
  for (Eigen::Index m = 0; m < M; ++m) {
    const double r2 = ((U.row(m).transpose() - x).array().square() *
                       inv_sq_lengthscales_.array()).sum();
    k(m) = signal_variance_ * std::exp(-0.5 * r2);
  }
  mean->resize(alpha_.cols());
  mean->noalias() = alpha_.transpose() * k;
  const double latent = signal_variance_ - k.dot(cov_correction_ * k);
  *variance = std::max(latent, 0.0) + noise_variance_;
}

}  // namespace iplan::intent

// Sparse pseudo-input Gaussian process (SPGP / FITC, Snelson & Ghahramani
// 2006) with an ARD squared-exponential kernel, for several outputs that share
// one set of pseudo-inputs and hyperparameters (independent outputs, zero mean).
//
//   k(x, x') = s_f^2 exp(-1/2 sum_d (x_d - x'_d)^2 / l_d^2)
//   y_p = f_p(x) + eps,  eps ~ N(0, s_n^2), independently for each output p.
// FITC: cov(y) = Q_nn + diag(K_nn - Q_nn) + s_n^2 I, Q_nn = K_nm K_mm^-1 K_mn.
// Inputs and outputs are in whatever units the caller uses (the forecaster
// standardises them); `D` input dimensions, `P` outputs, `M` pseudo-inputs.
#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

namespace iplan::intent {

/// Pseudo-inputs and kernel/noise hyperparameters.
struct SparseGpHyper {
  Eigen::MatrixXd pseudo_inputs;     ///< (M, D) pseudo-input locations.
  Eigen::VectorXd log_lengthscales;  ///< (D) log l_d.
  double log_signal_variance = 0.0;  ///< log s_f^2.
  double log_noise_variance = -2.0;  ///< log s_n^2.
};

struct SparseGpParams {
  int num_pseudo_inputs = 20;   ///< M (>= 1; capped at N).
  int max_iterations = 150;     ///< L-BFGS iterations (0: keep the initial guess).
  double jitter = 1e-6;         ///< Added to K_mm's diagonal, relative to s_f^2.
  std::uint64_t seed = 1;       ///< Seeds the choice of initial pseudo-inputs.

  /// Empty string when valid, else the offending field and value.
  std::string Validate() const;
};

/// FITC negative log marginal likelihood of outputs `Y` (N, P) at inputs `X`
/// (N, D), summed over outputs, and (if `gradient` is non-null) its gradient
/// with respect to the packed parameter vector [pseudo_inputs row-major (M D),
/// log_lengthscales (D), log_signal_variance, log_noise_variance].
/// Returns +infinity when a factorisation fails. Thread-safe.
double FitcNegLogLikelihood(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                            const SparseGpHyper& hyper, double jitter,
                            Eigen::VectorXd* gradient);

/// Packs / unpacks the parameter vector used by FitcNegLogLikelihood().
Eigen::VectorXd PackHyper(const SparseGpHyper& hyper);
SparseGpHyper UnpackHyper(const Eigen::VectorXd& theta, int M, int D);

/// A trained SPGP: hyperparameters plus the precomputed predictive terms.
/// Immutable after construction; const methods are thread-safe.
class SparseGp {
 public:
  SparseGp() = default;

  /// Builds the predictor for fixed `hyper` from data X (N, D), Y (N, P).
  /// Throws std::invalid_argument on size mismatch and std::runtime_error if
  /// the FITC matrices cannot be factorised.
  static SparseGp FromHyper(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                            const SparseGpHyper& hyper, double jitter);

  /// Initialises pseudo-inputs at a seeded random subset of X, lengthscales
  /// from the input spread, s_f^2 from the output variance, s_n^2 = s_f^2/10,
  /// then maximises the FITC marginal likelihood over all of them with
  /// L-BFGS (Ceres) and builds the predictor. Throws std::invalid_argument on
  /// bad sizes or params. `final_nll` (optional) receives the final FITC
  /// negative log-likelihood.
  static SparseGp Fit(const Eigen::MatrixXd& X, const Eigen::MatrixXd& Y,
                      const SparseGpParams& params, double* final_nll = nullptr);

  /// Predictive mean (P) of every output at input `x` (D) and the shared
  /// predictive variance of a noisy output (same for all outputs; latent
  /// variance + s_n^2). Does not allocate when `mean` has size P.
  void Predict(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::VectorXd* mean,
               double* variance) const;

  const SparseGpHyper& hyper() const { return hyper_; }
  int num_inputs() const { return static_cast<int>(hyper_.log_lengthscales.size()); }
  int num_outputs() const { return static_cast<int>(alpha_.cols()); }
  int num_pseudo_inputs() const { return static_cast<int>(hyper_.pseudo_inputs.rows()); }

  /// Raw access for model files: the precomputed terms. `alpha` (M, P) =
  /// B^-1 K_mn Lambda^-1 Y; `cov_correction` (M, M) = K_mm^-1 - B^-1.
  const Eigen::MatrixXd& alpha() const { return alpha_; }
  const Eigen::MatrixXd& cov_correction() const { return cov_correction_; }
  /// Reassembles a predictor from stored parts (no recomputation, so a
  /// saved-and-loaded model predicts bit-identically). Throws
  /// std::invalid_argument on inconsistent sizes.
  static SparseGp FromParts(SparseGpHyper hyper, Eigen::MatrixXd alpha,
                            Eigen::MatrixXd cov_correction);

 private:
  SparseGpHyper hyper_;
  Eigen::VectorXd inv_sq_lengthscales_;  // (D) 1 / l_d^2, derived.
  double signal_variance_ = 1.0;
  double noise_variance_ = 0.0;
  Eigen::MatrixXd alpha_;
  Eigen::MatrixXd cov_correction_;
  void Derive();
};

}  // namespace iplan::intent

// Multi-class Import Vector Machine (Zhu & Hastie 2005): kernel logistic
// regression whose kernel expansion uses a small, greedily chosen set of
// "import" training samples.
//
// Model: f_c(x) = sum_{s in S} k(x, x_s) alpha_{s,c} + b_c,
//        p(c | x) = exp(f_c) / sum_c' exp(f_c').
// Fit: minimise H = -(1/N) sum_i log p(y_i | x_i)
//                   + (lambda/2) sum_c alpha_c^T R_SS alpha_c,
// where R_SS = K_SS + delta I is the kernel among import samples shifted by
// delta = max(0, -smallest eigenvalue of the full training kernel) (indefinite
// kernels such as DTW are regularised this way; every R_SS is then PSD).
// Greedy selection: each round scores every remaining sample by the decrease
// of H that one (diagonal) Newton step on its new coefficients would give,
// adds the best, and refits all coefficients by damped block Newton. It stops
// when the relative decrease of H over the last `stop_window` additions is
// below `stop_tolerance`, or at `max_import` samples.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace iplan::intent {

struct IvmParams {
  double lambda = 1e-3;           ///< Regulariser (> 0).
  int max_import = 80;            ///< Upper bound on import samples (>= 1).
  int stop_window = 3;            ///< Delta k of the stopping rule (>= 1).
  double stop_tolerance = 1e-3;   ///< Relative decrease threshold (>= 0).
  int newton_iterations = 3;      ///< Newton refits after each addition (>= 1).

  /// Empty string when valid, else the offending field and value.
  std::string Validate() const;
};

/// A fitted IVM. Plain data; const methods are thread-safe.
struct IvmModel {
  Eigen::VectorXi import_index;  ///< (q) indices of import samples in the training set.
  Eigen::MatrixXd alpha;         ///< (q, C) kernel expansion coefficients.
  Eigen::VectorXd bias;          ///< (C) class offsets.

  int num_classes() const { return static_cast<int>(bias.size()); }
  /// Class probabilities (C) for a sample given its kernel values to the
  /// import samples, `k` (q). Sums to 1. Does not allocate when `p` has size C.
  void Probabilities(const Eigen::Ref<const Eigen::VectorXd>& k,
                     Eigen::VectorXd* p) const;
};

struct IvmFitSummary {
  std::vector<double> objective;  ///< H after each addition (index 0: bias only).
};

/// Fits an IVM. `K` (N, N) is the symmetric kernel matrix of the training
/// samples, `labels` (N) their classes in [0, num_classes). Deterministic.
/// Throws std::invalid_argument on size mismatches, labels out of range or
/// invalid params.
IvmModel FitIvm(const Eigen::MatrixXd& K, const std::vector<int>& labels,
                int num_classes, const IvmParams& params,
                IvmFitSummary* summary = nullptr);

/// Mean negative log-likelihood of `labels` under probabilities `P` (N, C),
/// with probabilities floored at 1e-12.
double MeanLogLoss(const Eigen::MatrixXd& P, const std::vector<int>& labels);

}  // namespace iplan::intent

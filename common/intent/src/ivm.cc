#include "iplan/intent/ivm.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace iplan::intent {
namespace {

// Row-wise softmax of F (N, C) into P.
void Softmax(const Eigen::MatrixXd& F, Eigen::MatrixXd* P) {
  P->resize(F.rows(), F.cols());
  for (Eigen::Index i = 0; i < F.rows(); ++i) {
    const double mx = F.row(i).maxCoeff();
    double s = 0.0;
    for (Eigen::Index c = 0; c < F.cols(); ++c) {
      const double e = std::exp(F(i, c) - mx);
      (*P)(i, c) = e;
      s += e;
    }
    P->row(i) /= s;
  }
}

// Diagonal shift that makes a symmetric matrix positive semi-definite: every
// principal submatrix of K + shift I is then PSD too, so the penalty of a
// growing import set stays consistent (the objective never increases when a
// sample is added).
double PsdShift(const Eigen::MatrixXd& K) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (K + K.transpose()),
                                                    Eigen::EigenvaluesOnly);
  const double min_ev = es.eigenvalues().minCoeff();
  return std::max(0.0, -min_ev) + 1e-10 * std::max(1.0, es.eigenvalues().maxCoeff());
}

struct Fitter {
  const Eigen::MatrixXd& K;
  const std::vector<int>& labels;
  int C;
  double lambda;
  Eigen::Index N;
  Eigen::MatrixXd Y;  // (N, C) one-hot

  double Objective(const Eigen::MatrixXd& KnS, const Eigen::MatrixXd& R,
                   const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                   Eigen::MatrixXd* P) const {
    Eigen::MatrixXd F = KnS * A;
    F.rowwise() += b.transpose();
    Softmax(F, P);
    double nll = 0.0;
    for (Eigen::Index i = 0; i < N; ++i) {
      nll -= std::log(std::max((*P)(i, labels[i]), 1e-300));
    }
    double pen = 0.0;
    if (A.rows() > 0) pen = (A.transpose() * R * A).trace();
    return nll / N + 0.5 * lambda * pen;
  }
};

// The greedy fit so far: import set S (q), its kernel columns KnS (N, q),
// the penalty matrix R = K_SS + shift I (q, q), coefficients A (q, C) and
// bias b (C), the probabilities P (N, C) and the objective H they give.
struct ImportFit {
  std::vector<Eigen::Index> S;
  Eigen::MatrixXd A, KnS, R, P;
  Eigen::VectorXd b;
  double H = 0.0;
};

void CheckFitInput(const Eigen::MatrixXd& K, const std::vector<int>& labels, int num_classes,
                   const IvmParams& params) {
  const std::string error = params.Validate();
  if (!error.empty()) throw std::invalid_argument("IvmParams: " + error);
  const Eigen::Index N = K.rows();
  if (N < 1 || K.cols() != N || static_cast<Eigen::Index>(labels.size()) != N ||
      num_classes < 2) {
    throw std::invalid_argument(
        "FitIvm: kernel (" + std::to_string(K.rows()) + " x " +
        std::to_string(K.cols()) + "), " + std::to_string(labels.size()) +
        " labels, " + std::to_string(num_classes) +
        " classes: need a square kernel, one label per sample, >= 2 classes");
  }
  for (int y : labels) {
    if (y < 0 || y >= num_classes) {
      throw std::invalid_argument("FitIvm: label " + std::to_string(y) +
                                  " outside [0, " + std::to_string(num_classes) + ")");
    }
  }
}

// Score all candidates by a diagonal Newton step on their new row; the best
// one not in the set (-1 when none is left).
Eigen::Index BestCandidate(const Fitter& fit, const ImportFit& s, const Eigen::MatrixXd& K2,
                           const std::vector<char>& in_set, double shift) {
  const Eigen::MatrixXd& K = fit.K;
  const Eigen::Index N = fit.N;
  const int C = fit.C;
  const Eigen::MatrixXd G0 = K.transpose() * (s.P - fit.Y) / static_cast<double>(N);
  const Eigen::MatrixXd W = s.P.cwiseProduct((1.0 - s.P.array()).matrix());
  const Eigen::MatrixXd Hd = K2.transpose() * W / static_cast<double>(N);
  Eigen::MatrixXd cross;
  if (!s.S.empty()) cross = s.KnS * s.A;  // (N, C): row l is K_lS alpha (K symmetric)
  Eigen::Index best = -1;
  double best_score = -1.0;
  for (Eigen::Index l = 0; l < N; ++l) {
    if (in_set[l]) continue;
    double score = 0.0;
    for (int c = 0; c < C; ++c) {
      double g = G0(l, c);
      if (!s.S.empty()) g += fit.lambda * cross(l, c);
      const double h = Hd(l, c) + fit.lambda * (K(l, l) + shift) + 1e-12;
      score += g * g / (2.0 * h);
    }
    if (score > best_score) {
      best_score = score;
      best = l;
    }
  }
  return best;
}

// Adds sample `best` to the import set with zero coefficients.
void AddImport(const Fitter& fit, Eigen::Index best, double shift, ImportFit* s) {
  const Eigen::MatrixXd& K = fit.K;
  s->S.push_back(best);
  const Eigen::Index q = static_cast<Eigen::Index>(s->S.size());
  s->KnS.conservativeResize(fit.N, q);
  s->KnS.col(q - 1) = K.col(best);
  Eigen::MatrixXd KSS(q, q);
  for (Eigen::Index r = 0; r < q; ++r) {
    for (Eigen::Index c = 0; c < q; ++c) KSS(r, c) = K(s->S[r], s->S[c]);
  }
  s->R = KSS;
  s->R.diagonal().array() += shift;
  s->A.conservativeResize(q, fit.C);
  s->A.row(q - 1).setZero();
  s->H = fit.Objective(s->KnS, s->R, s->A, s->b, &s->P);
}

// Damped block Newton (one block per class) on [alpha_c; b_c].
void RefitNewton(const Fitter& fit, int newton_iterations, ImportFit* s) {
  const Eigen::Index N = fit.N;
  const Eigen::Index q = static_cast<Eigen::Index>(s->S.size());
  Eigen::MatrixXd X(N, q + 1);
  X.leftCols(q) = s->KnS;
  X.col(q).setOnes();
  for (int it = 0; it < newton_iterations; ++it) {
    Eigen::MatrixXd dA(q, fit.C);
    Eigen::VectorXd db(fit.C);
    for (int c = 0; c < fit.C; ++c) {
      const Eigen::VectorXd w = s->P.col(c).cwiseProduct((1.0 - s->P.col(c).array()).matrix());
      Eigen::MatrixXd Hc = X.transpose() * w.asDiagonal() * X / static_cast<double>(N);
      Hc.topLeftCorner(q, q) += fit.lambda * s->R;
      Hc.diagonal().array() += 1e-9;
      Eigen::VectorXd g = X.transpose() * (s->P.col(c) - fit.Y.col(c)) / static_cast<double>(N);
      g.head(q) += fit.lambda * (s->R * s->A.col(c));
      const Eigen::VectorXd step = -Hc.ldlt().solve(g);
      dA.col(c) = step.head(q);
      db(c) = step(q);
    }
    double t = 1.0;
    bool improved = false;
    Eigen::MatrixXd Ptry;
    for (int ls = 0; ls < 12; ++ls) {
      const Eigen::MatrixXd Atry = s->A + t * dA;
      const Eigen::VectorXd btry = s->b + t * db;
      const double Htry = fit.Objective(s->KnS, s->R, Atry, btry, &Ptry);
      if (std::isfinite(Htry) && Htry < s->H) {
        s->A = Atry;
        s->b = btry;
        s->P = Ptry;
        const double rel = (s->H - Htry) / std::max(std::abs(s->H), 1e-12);
        s->H = Htry;
        improved = rel > 1e-9;
        break;
      }
      t *= 0.5;
    }
    if (!improved) break;
  }
}

}  // namespace

std::string IvmParams::Validate() const {
  if (!(lambda > 0.0)) return "lambda " + std::to_string(lambda) + " must be > 0";
  if (max_import < 1) return "max_import " + std::to_string(max_import) + " must be >= 1";
  if (stop_window < 1) return "stop_window " + std::to_string(stop_window) + " must be >= 1";
  if (!(stop_tolerance >= 0.0)) return "stop_tolerance must be >= 0";
  if (newton_iterations < 1) return "newton_iterations must be >= 1";
  return "";
}

void IvmModel::Probabilities(const Eigen::Ref<const Eigen::VectorXd>& k,
                             Eigen::VectorXd* p) const {
  p->resize(bias.size());
  p->noalias() = alpha.transpose() * k;
  *p += bias;
  const double mx = p->maxCoeff();
  *p = (p->array() - mx).exp();
  *p /= p->sum();
}

double MeanLogLoss(const Eigen::MatrixXd& P, const std::vector<int>& labels) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    s -= std::log(std::max(P(i, labels[i]), 1e-12));
  }
  return P.rows() > 0 ? s / P.rows() : 0.0;
}


IvmModel FitIvm(const Eigen::MatrixXd& K, const std::vector<int>& labels,
                int num_classes, const IvmParams& params,
                IvmFitSummary* summary) {
  CheckFitInput(K, labels, num_classes, params);
  const Eigen::Index N = K.rows();
  const int C = num_classes;
  Fitter fit{K, labels, C, params.lambda, N, Eigen::MatrixXd::Zero(N, C)};
  for (Eigen::Index i = 0; i < N; ++i) fit.Y(i, labels[i]) = 1.0;

  // Start: bias only, at the class log-frequencies (the optimum without kernel
  // terms); a small floor keeps absent classes finite.
  ImportFit s;
  s.b.resize(C);
  for (int c = 0; c < C; ++c) {
    s.b(c) = std::log((fit.Y.col(c).sum() + 1e-3) / (N + C * 1e-3));
  }
  s.A.resize(0, C);
  s.KnS.resize(N, 0);
  s.R.resize(0, 0);
  s.H = fit.Objective(s.KnS, s.R, s.A, s.b, &s.P);
  std::vector<double> history{s.H};
  const Eigen::MatrixXd K2 = K.cwiseProduct(K);
  std::vector<char> in_set(N, 0);
  const double shift = PsdShift(K);

  const int max_import = static_cast<int>(std::min<Eigen::Index>(params.max_import, N));
  while (static_cast<int>(s.S.size()) < max_import) {
    const Eigen::Index best = BestCandidate(fit, s, K2, in_set, shift);
    if (best < 0) break;
    in_set[best] = 1;
    AddImport(fit, best, shift, &s);
    RefitNewton(fit, params.newton_iterations, &s);
    history.push_back(s.H);
    const int k = static_cast<int>(history.size()) - 1;
    if (k >= params.stop_window) {
      const double before = history[k - params.stop_window];
      if ((before - s.H) / std::max(std::abs(s.H), 1e-12) < params.stop_tolerance) break;
    }
  }

  IvmModel model;
  model.import_index.resize(static_cast<Eigen::Index>(s.S.size()));
  for (size_t i = 0; i < s.S.size(); ++i) model.import_index(i) = static_cast<int>(s.S[i]);
  model.alpha = s.A;
  model.bias = s.b;
  if (summary != nullptr) summary->objective = history;
  return model;
}

}  // namespace iplan::intent

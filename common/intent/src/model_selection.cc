#include "iplan/intent/model_selection.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace iplan::intent {

int SimplestWithinOneStandardError(const Eigen::MatrixXd& fold_error) {
  const Eigen::Index O = fold_error.rows();
  std::vector<Eigen::Index> folds;  // folds every option was scored on
  for (Eigen::Index f = 0; f < fold_error.cols(); ++f) {
    if (fold_error.col(f).allFinite()) folds.push_back(f);
  }
  if (folds.empty()) return 0;
  const double F = static_cast<double>(folds.size());
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(O);
  for (Eigen::Index f : folds) mean += fold_error.col(f);
  mean /= F;
  Eigen::Index best = 0;
  mean.minCoeff(&best);
  if (folds.size() < 2) return static_cast<int>(best);
  for (Eigen::Index o = 0; o < O; ++o) {
    double d = 0.0, d2 = 0.0;
    for (Eigen::Index f : folds) {
      const double diff = fold_error(o, f) - fold_error(best, f);
      d += diff;
      d2 += diff * diff;
    }
    d /= F;
    const double se = std::sqrt(std::max(0.0, (d2 / F - d * d) * F / (F - 1.0)) / F);
    if (d <= se) return static_cast<int>(o);
  }
  return static_cast<int>(best);
}

}  // namespace iplan::intent

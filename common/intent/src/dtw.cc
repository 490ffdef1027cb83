#include "iplan/intent/dtw.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

namespace iplan::intent {

double DtwDistanceColumns(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                          int band, std::vector<double>* workspace) {
  assert(a.rows() == b.rows() && a.cols() > 0 && b.cols() > 0);
  const int n = static_cast<int>(a.cols());
  const int m = static_cast<int>(b.cols());
  const int d = static_cast<int>(a.rows());
  const int w = band < 0 ? std::max(n, m) : std::max(band, std::abs(n - m));
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // Two rows of the accumulated-cost table, each with a sentinel in front.
  workspace->assign(2 * (m + 1), kInf);
  double* prev = workspace->data();
  double* cur = prev + (m + 1);
  prev[0] = 0.0;  // D(-1, -1) = 0: the only entry to (0, 0).
  for (int i = 0; i < n; ++i) {
    const int j_lo = std::max(0, i - w);
    const int j_hi = std::min(m - 1, i + w);
    std::fill(cur, cur + m + 1, kInf);
    const double* ai = a.col(i).data();
    for (int j = j_lo; j <= j_hi; ++j) {
      const double* bj = b.col(j).data();
      double s = 0.0;
      for (int k = 0; k < d; ++k) {
        const double e = ai[k] - bj[k];
        s += e * e;
      }
      // cur[j + 1] is D(i, j); prev[j + 1] is D(i-1, j).
      const double best = std::min({prev[j], prev[j + 1], cur[j]});
      cur[j + 1] = std::sqrt(s) + best;
    }
    std::swap(prev, cur);  // `cur` is refilled with +inf at the next row.
  }
  return prev[m];
}

double DtwDistance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, int band) {
  if (a.rows() == 0 || b.rows() == 0 || a.cols() == 0 || a.cols() != b.cols()) {
    throw std::invalid_argument(
        "DtwDistance: need non-empty sequences with the same frame size, got (" +
        std::to_string(a.rows()) + " x " + std::to_string(a.cols()) + ") and (" +
        std::to_string(b.rows()) + " x " + std::to_string(b.cols()) + ")");
  }
  std::vector<double> ws;
  const Eigen::MatrixXd at = a.transpose();
  const Eigen::MatrixXd bt = b.transpose();
  return DtwDistanceColumns(at, bt, band, &ws);
}

double DtwKernel(double dtw, double sigma) {
  return std::exp(-dtw * dtw / (2.0 * sigma * sigma));
}

}  // namespace iplan::intent

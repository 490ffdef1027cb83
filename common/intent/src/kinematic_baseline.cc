#include "iplan/intent/kinematic_baseline.h"

#include <algorithm>
#include <cmath>

namespace iplan::intent {

std::string KinematicBaseline::Validate() const {
  if (smoothing_frames < 1) {
    return "smoothing_frames " + std::to_string(smoothing_frames) + " must be >= 1";
  }
  if (!(damping_time_constant >= 0.0)) {  // also rejects NaN; +infinity is allowed
    return "damping_time_constant " + std::to_string(damping_time_constant) + " must be >= 0 s";
  }
  return "";
}

namespace {

// The least-squares line through rows first..first+L-1 of column `col`, at
// times s_i = i - (L - 1) frames: value at s = 0 and slope per frame.
void FitColumn(const Eigen::Ref<const Eigen::MatrixXd>& rows, Eigen::Index first,
               Eigen::Index L, Eigen::Index col, double* value, double* slope) {
  if (L == 1) {
    *value = rows(first, col);
    *slope = 0.0;
    return;
  }
  const double s_mean = -0.5 * static_cast<double>(L - 1);
  double mean = 0.0;
  for (Eigen::Index i = 0; i < L; ++i) mean += rows(first + i, col);
  mean /= static_cast<double>(L);
  double cov = 0.0, var = 0.0;
  for (Eigen::Index i = 0; i < L; ++i) {
    const double c = static_cast<double>(i - (L - 1)) - s_mean;
    cov += c * (rows(first + i, col) - mean);
    var += c * c;
  }
  *slope = cov / var;
  *value = mean - *slope * s_mean;
}

Eigen::Index UsedRows(Eigen::Index n, int frames) {
  return std::max<Eigen::Index>(1, std::min<Eigen::Index>(frames, n));
}

}  // namespace

void FitLine(const Eigen::Ref<const Eigen::MatrixXd>& rows, int frames, double rate,
             Eigen::VectorXd* position, Eigen::VectorXd* velocity) {
  const Eigen::Index n = rows.rows(), d = rows.cols();
  const Eigen::Index L = UsedRows(n, frames);
  position->resize(d);
  velocity->resize(d);
  for (Eigen::Index col = 0; col < d; ++col) {
    double slope = 0.0;
    FitColumn(rows, n - L, L, col, &(*position)(col), &slope);
    (*velocity)(col) = slope * rate;
  }
}

double DampedDisplacement(double t, double tau) {
  if (std::isinf(tau)) return t;
  if (!(tau > 0.0)) return 0.0;
  return -tau * std::expm1(-t / tau);
}

void ExtrapolateKinematic(const Eigen::Ref<const Eigen::MatrixXd>& window,
                          const KinematicBaseline& baseline, double rate, int horizon,
                          Eigen::MatrixXd* out) {
  const Eigen::Index n = window.rows(), d = window.cols();
  const Eigen::Index L = UsedRows(n, baseline.smoothing_frames);
  out->resize(horizon, d);
  for (Eigen::Index col = 0; col < d; ++col) {
    double value = 0.0, slope = 0.0;
    FitColumn(window, n - L, L, col, &value, &slope);
    for (int k = 0; k < horizon; ++k) {
      (*out)(k, col) =
          value + slope * rate * DampedDisplacement((k + 1) / rate, baseline.damping_time_constant);
    }
  }
}

void MeanJointSpeeds(const Eigen::Ref<const Eigen::MatrixXd>& window, double rate,
                     Eigen::VectorXd* speeds) {
  const Eigen::Index n = window.rows(), J = window.cols() / 3;
  speeds->setZero(J);
  if (n < 2) return;
  for (Eigen::Index j = 0; j < J; ++j) {
    double path = 0.0;
    for (Eigen::Index r = 1; r < n; ++r) {
      path += (window.block<1, 3>(r, 3 * j) - window.block<1, 3>(r - 1, 3 * j)).norm();
    }
    (*speeds)(j) = path * rate / static_cast<double>(n - 1);
  }
}

}  // namespace iplan::intent

#include "iplan/intent/belief_filter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace iplan::intent {

std::string BeliefFilterParams::Validate() const {
  if (!(time_constant >= 0.0)) {  // also rejects NaN; +infinity is allowed
    return "time_constant " + std::to_string(time_constant) + " must be >= 0 s";
  }
  if (!(min_probability > 0.0 && min_probability < 1.0)) {
    return "min_probability " + std::to_string(min_probability) + " must be in (0, 1)";
  }
  return "";
}

BeliefFilter::BeliefFilter(int num_classes, BeliefFilterParams params) : params_(params) {
  if (num_classes < 1) {
    throw std::invalid_argument("BeliefFilter: need >= 1 class, got " + std::to_string(num_classes));
  }
  if (const std::string why = params_.Validate(); !why.empty()) {
    throw std::invalid_argument("BeliefFilterParams: " + why);
  }
  log_sum_ = Eigen::VectorXd::Zero(num_classes);
  belief_ = Eigen::VectorXd::Constant(num_classes, 1.0 / num_classes);
}

void BeliefFilter::Reset() {
  log_sum_.setZero();
  weight_sum_ = 0.0;
  last_stamp_ = 0.0;
  num_updates_ = 0;
  belief_.setConstant(1.0 / static_cast<double>(belief_.size()));
}

double WindowMotion(const Eigen::MatrixXd& window) {
  const Eigen::Index J = window.cols() / 3;
  if (window.rows() < 2 || J == 0) return 0.0;
  double path = 0.0;
  for (Eigen::Index r = 0; r + 1 < window.rows(); ++r) {
    for (Eigen::Index j = 0; j < J; ++j) {
      path += (window.block(r + 1, 3 * j, 1, 3) - window.block(r, 3 * j, 1, 3)).norm();
    }
  }
  return path / static_cast<double>(J);
}

void BeliefFilter::UpdateWithWindow(const Eigen::VectorXd& p, const Eigen::MatrixXd& window,
                                    int full_rows, double stamp) {
  if (window.rows() < full_rows) Reset();
  Update(p, stamp, params_.motion_weighted ? std::max(WindowMotion(window), 1e-6) : 1.0);
}

void BeliefFilter::Update(const Eigen::VectorXd& p, double stamp, double weight) {
  if (!(weight > 0.0) || !std::isfinite(weight)) {
    throw std::invalid_argument("BeliefFilter::Update: weight " + std::to_string(weight) +
                                " must be > 0 and finite");
  }
  if (p.size() != log_sum_.size()) {
    throw std::invalid_argument("BeliefFilter::Update: " + std::to_string(p.size()) +
                                " probabilities for " + std::to_string(log_sum_.size()) + " classes");
  }
  if (!p.allFinite() || !std::isfinite(stamp)) {
    throw std::invalid_argument("BeliefFilter::Update: non-finite probability or stamp");
  }
  if (num_updates_ > 0) {
    const double dt = stamp - last_stamp_;
    if (dt < 0.0) throw std::invalid_argument("BeliefFilter::Update: stamp goes backwards");
    // Old weights relative to the new update: exp(-dt / tau); tau = 0 keeps
    // only the newest window, tau = inf keeps everything.
    double decay = 1.0;
    if (params_.time_constant == 0.0) {
      decay = 0.0;
    } else if (std::isfinite(params_.time_constant)) {
      decay = std::exp(-dt / params_.time_constant);
    }
    log_sum_ *= decay;
    weight_sum_ *= decay;
  }
  for (Eigen::Index c = 0; c < p.size(); ++c) {
    log_sum_(c) += weight * std::log(std::max(p(c), params_.min_probability));
  }
  weight_sum_ += weight;
  last_stamp_ = stamp;
  ++num_updates_;
  // Normalised geometric mean (softmax of the weighted mean log-probability).
  const double inv_w = 1.0 / weight_sum_;
  const double top = log_sum_.maxCoeff() * inv_w;
  double total = 0.0;
  for (Eigen::Index c = 0; c < p.size(); ++c) {
    belief_(c) = std::exp(log_sum_(c) * inv_w - top);
    total += belief_(c);
  }
  belief_ /= total;
}

int BeliefFilter::MostLikely() const {
  Eigen::Index best = 0;
  belief_.maxCoeff(&best);
  return static_cast<int>(best);
}

}  // namespace iplan::intent

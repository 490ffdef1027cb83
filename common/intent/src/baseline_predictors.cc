#include "iplan/intent/baseline_predictors.h"

#include <cmath>
#include <stdexcept>

namespace iplan::intent {

const char* ToString(BaselineKind kind) {
  return kind == BaselineKind::kConstantPosition ? "constant_position" : "constant_velocity";
}

std::string BaselinePredictorParams::Validate() const {
  auto bad = [](const char* name, double v, const char* rule) {
    return std::string(name) + " " + std::to_string(v) + " must be " + rule;
  };
  if (!(rate > 0) || !std::isfinite(rate)) return bad("rate", rate, "> 0 Hz");
  if (horizon < 1) return "horizon " + std::to_string(horizon) + " must be >= 1";
  if (!(window > 0) || !std::isfinite(window)) return bad("window", window, "> 0 s");
  if (!(sensor_noise_std >= 0) || !std::isfinite(sensor_noise_std)) return bad("sensor_noise_std", sensor_noise_std, ">= 0 m");
  if (!(speed_std >= 0) || !std::isfinite(speed_std)) return bad("speed_std", speed_std, ">= 0 m/s");
  if (!(acceleration_std >= 0) || !std::isfinite(acceleration_std)) {
    return bad("acceleration_std", acceleration_std, ">= 0 m/s^2");
  }
  return "";
}

void PredictBaseline(const BaselinePredictorParams& params, const Eigen::VectorXd& stamps,
                     const Eigen::MatrixXd& positions, MixturePrediction* out) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument("baseline predictor: " + why);
  const Eigen::Index n = stamps.size();
  if (n < 1) throw std::invalid_argument("baseline predictor: no frames");
  if (positions.rows() != n) {
    throw std::invalid_argument("baseline predictor: " + std::to_string(n) + " stamps but " +
                                std::to_string(positions.rows()) + " frames");
  }
  if (positions.cols() < 3 || positions.cols() % 3 != 0) {
    throw std::invalid_argument("baseline predictor: " + std::to_string(positions.cols()) +
                                " position columns, not 3 per joint");
  }
  if (!stamps.allFinite() || !positions.allFinite()) throw std::invalid_argument("baseline predictor: non-finite input");
  for (Eigen::Index i = 1; i < n; ++i) {
    if (!(stamps(i) > stamps(i - 1))) throw std::invalid_argument("baseline predictor: stamps do not increase");
  }
  const int J = static_cast<int>(positions.cols() / 3);
  const double t0 = stamps(n - 1);
  const double noise = params.sensor_noise_std * params.sensor_noise_std;

  // Frames of the fit: the newest ones within the window (a tiny tolerance so
  // that a frame exactly `window` old at a 30 Hz grid is not lost to rounding).
  Eigen::Index first = n - 1;
  while (first > 0 && t0 - stamps(first - 1) <= params.window + 1e-9) --first;
  const Eigen::Index m = n - first;
  const bool fit = params.kind == BaselineKind::kConstantVelocity && m >= 2;

  // Least squares p(tau) = a + b (tau - tbar), tau = stamp - t0 (<= 0).
  double tbar = 0, stt = 0;
  Eigen::RowVectorXd a = positions.row(n - 1), b = Eigen::RowVectorXd::Zero(positions.cols());
  if (fit) {
    const Eigen::VectorXd tau = stamps.segment(first, m).array() - t0;
    tbar = tau.mean();
    const Eigen::VectorXd dtau = tau.array() - tbar;
    stt = dtau.squaredNorm();
    const Eigen::MatrixXd block = positions.middleRows(first, m);
    a = block.colwise().mean();
    b = (dtau.transpose() * (block.rowwise() - a)) / stt;
  }

  out->dt = 1.0 / params.rate;
  out->horizon = params.horizon;
  out->num_joints = J;
  out->actions.resize(1);
  ActionHypothesis& h = out->actions[0];
  h.action = ToString(params.kind);
  h.probability = 1.0;
  h.joints.resize(static_cast<std::size_t>(params.horizon) * static_cast<std::size_t>(J));
  for (int k = 0; k < params.horizon; ++k) {
    const double t = (k + 1) / params.rate;
    double var = noise;
    Eigen::RowVectorXd mean;
    if (fit) {
      mean = a + (t - tbar) * b;
      const double accel = 0.5 * params.acceleration_std * t * t;
      var += noise * (1.0 / static_cast<double>(m) + (t - tbar) * (t - tbar) / stt) + accel * accel;
    } else {
      mean = a;
      const double spread = params.speed_std * t;
      var += spread * spread;
    }
    for (int j = 0; j < J; ++j) {
      JointGaussian& g = h.joints[static_cast<std::size_t>(k) * static_cast<std::size_t>(J) + static_cast<std::size_t>(j)];
      g.mean = mean.segment<3>(3 * j).transpose();
      g.covariance = var * Eigen::Matrix3d::Identity();
    }
  }
}

BaselinePredictor::BaselinePredictor(BaselinePredictorParams params, int num_joints)
    : params_(params), num_joints_(num_joints) {
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument("baseline predictor: " + why);
  if (num_joints_ < 1) throw std::invalid_argument("baseline predictor: num_joints must be >= 1");
}

void BaselinePredictor::Reset() {
  stamps_.clear();
  positions_.clear();
}

void BaselinePredictor::Update(double stamp, const Eigen::VectorXd& positions, MixturePrediction* out) {
  if (positions.size() != 3 * num_joints_) {
    throw std::invalid_argument("baseline predictor: frame has " + std::to_string(positions.size()) +
                                " coordinates, expected " + std::to_string(3 * num_joints_));
  }
  if (!std::isfinite(stamp) || !positions.allFinite()) throw std::invalid_argument("baseline predictor: non-finite frame");
  if (!stamps_.empty() && !(stamp > stamps_.back())) {
    throw std::invalid_argument("baseline predictor: stamp " + std::to_string(stamp) + " s is not after " +
                                std::to_string(stamps_.back()) + " s");
  }
  stamps_.push_back(stamp);
  positions_.push_back(positions);
  // Only the fit window is ever used.
  while (!stamps_.empty() && stamp - stamps_.front() > params_.window + 1e-9) {
    stamps_.pop_front();
    positions_.pop_front();
  }
  const Eigen::Index n = static_cast<Eigen::Index>(stamps_.size());
  stamp_buffer_.resize(n);
  position_buffer_.resize(n, 3 * num_joints_);
  for (Eigen::Index i = 0; i < n; ++i) {
    stamp_buffer_(i) = stamps_[static_cast<std::size_t>(i)];
    position_buffer_.row(i) = positions_[static_cast<std::size_t>(i)].transpose();
  }
  PredictBaseline(params_, stamp_buffer_, position_buffer_, out);
}

}  // namespace iplan::intent

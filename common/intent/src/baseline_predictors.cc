#include "iplan/intent/baseline_predictors.h"

#include <algorithm>
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
  for (std::size_t j = 0; j < joint_growth.size(); ++j) {
    if (!(joint_growth[j] >= 0) || !std::isfinite(joint_growth[j])) {
      return "joint_growth[" + std::to_string(j) + "] " + std::to_string(joint_growth[j]) + " must be >= 0";
    }
  }
  return "";
}

void PredictBaseline(const BaselinePredictorParams& params, const Eigen::VectorXd& stamps,
                     const Eigen::MatrixXd& positions, JointMixture* out) {
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
  if (!params.joint_growth.empty() && static_cast<int>(params.joint_growth.size()) != J) {
    throw std::invalid_argument("baseline predictor: " + std::to_string(params.joint_growth.size()) +
                                " joint growths for " + std::to_string(J) + " joints");
  }
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

  out->time_step = 1.0 / params.rate;
  out->Resize(1, params.horizon, J);
  out->actions[0] = ToString(params.kind);
  out->probabilities[0] = 1.0;
  // Constant velocity with one frame falls back to constant position, and
  // then grows as constant position does.
  const double scalar = fit ? params.acceleration_std : params.speed_std;
  const bool per_joint = !params.joint_growth.empty() && (fit || params.kind == BaselineKind::kConstantPosition);
  for (int k = 0; k < params.horizon; ++k) {
    const double t = (k + 1) / params.rate;
    double base = noise;
    Eigen::RowVectorXd mean;
    if (fit) {
      mean = a + (t - tbar) * b;
      base += noise * (1.0 / static_cast<double>(m) + (t - tbar) * (t - tbar) / stt);
    } else {
      mean = a;
    }
    // The growth's shape: t for an unknown speed, t^2 / 2 for an unknown acceleration.
    const double shape = fit ? 0.5 * t * t : t;
    for (int j = 0; j < J; ++j) {
      const double spread = (per_joint ? params.joint_growth[static_cast<std::size_t>(j)] : scalar) * shape;
      const std::size_t i = static_cast<std::size_t>(k) * static_cast<std::size_t>(J) + static_cast<std::size_t>(j);
      out->means[0][i] = mean.segment<3>(3 * j).transpose();
      out->covariances[0][i] = (base + spread * spread) * Eigen::Matrix3d::Identity();
    }
  }
}

std::vector<double> CalibrateBaselineGrowth(const BaselinePredictorParams& params, const SkeletonDataset& data,
                                            const std::vector<std::string>& joints) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument("baseline predictor: " + why);
  const std::vector<int> columns = JointIndices(data.joint_names, joints);
  const int J = static_cast<int>(joints.size());
  const int H = params.horizon;
  // The base variance of each prediction (noise and fit) is its covariance
  // without growth.
  BaselinePredictorParams no_growth = params;
  no_growth.joint_growth.assign(static_cast<std::size_t>(J), 0.0);
  Eigen::MatrixXd error = Eigen::MatrixXd::Zero(J, H);  // summed squared error per coordinate
  Eigen::VectorXd base = Eigen::VectorXd::Zero(H), count = Eigen::VectorXd::Zero(H);
  JointMixture out;
  for (const SkeletonSequence& seq : data.sequences) {
    // The usable frames: every selected joint detected.
    std::vector<double> stamps;
    std::vector<Eigen::VectorXd> frames;
    for (Eigen::Index i = 0; i < seq.positions.rows(); ++i) {
      Eigen::VectorXd p(3 * J);
      bool ok = true;
      for (int j = 0; j < J && ok; ++j) {
        const Eigen::RowVectorXd q = seq.positions.row(i).segment(3 * columns[static_cast<std::size_t>(j)], 3);
        ok = JointDetected(q);
        p.segment<3>(3 * j) = q.transpose();
      }
      if (!ok || (!stamps.empty() && !(seq.time(i) > stamps.back()))) continue;
      stamps.push_back(seq.time(i));
      frames.push_back(p);
    }
    BaselinePredictor predictor(no_growth, J);
    for (std::size_t i = 0; i < stamps.size(); ++i) {
      predictor.Update(stamps[i], frames[i], &out);
      if (stamps[i] - stamps.front() < params.window) continue;  // not a full window of history yet
      std::size_t seg = i;
      for (int k = 0; k < H; ++k) {
        const double t = stamps[i] + (k + 1) / params.rate;
        if (t > stamps.back()) break;
        while (seg + 1 < stamps.size() && stamps[seg + 1] < t) ++seg;
        const std::size_t next = std::min(seg + 1, stamps.size() - 1);
        const double u = next == seg ? 0.0 : (t - stamps[seg]) / (stamps[next] - stamps[seg]);
        const Eigen::VectorXd truth = (1 - u) * frames[seg] + u * frames[next];
        for (int j = 0; j < J; ++j) {
          error(j, k) += (out.Mean(0, k, j) - truth.segment<3>(3 * j)).squaredNorm() / 3.0;
        }
        base(k) += out.Covariance(0, k, 0)(0, 0);
        count(k) += 1;
      }
    }
  }
  if (count.sum() == 0) throw std::invalid_argument("baseline calibration: no sequence long enough to predict from");
  std::vector<double> growth(static_cast<std::size_t>(J), 0.0);
  for (int j = 0; j < J; ++j) {
    double num = 0, den = 0;
    for (int k = 0; k < H; ++k) {
      if (count(k) == 0) continue;
      const double t = (k + 1) / params.rate;
      const double phi = params.kind == BaselineKind::kConstantVelocity ? 0.25 * t * t * t * t : t * t;
      num += phi * (error(j, k) - base(k)) / count(k);
      den += phi * phi;
    }
    growth[static_cast<std::size_t>(j)] = std::sqrt(std::max(0.0, num / den));
  }
  return growth;
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

void BaselinePredictor::Update(double stamp, const Eigen::VectorXd& positions, JointMixture* out) {
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

#include "services/intent/core/intent_estimator.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "iplan/intent/skeleton_data.h"

namespace iplan::intent_service {

std::string IntentEstimatorParams::Validate() const {
  if (!(body_timeout > 0) || !std::isfinite(body_timeout)) {
    return "body_timeout must be > 0 s, got " + std::to_string(body_timeout);
  }
  if (!(max_gap > 0) || !std::isfinite(max_gap)) return "max_gap must be > 0 s, got " + std::to_string(max_gap);
  if (max_bodies < 1 || max_bodies > 1000) return "max_bodies must be in [1, 1000], got " + std::to_string(max_bodies);
  if (const std::string why = CoverageParams().Validate(); !why.empty()) return "coverage_" + why;
  return "";
}

intent::CoverageAdapterParams IntentEstimatorParams::CoverageParams() const {
  intent::CoverageAdapterParams p;
  p.halving_time = coverage_halving_time;
  p.carry_over = coverage_carry_over;
  return p;
}

const char* ToString(FrameStatus status) {
  switch (status) {
    case FrameStatus::kAccepted: return "accepted";
    case FrameStatus::kMissingJoint: return "missing_joint";
    case FrameStatus::kDuplicateJoint: return "duplicate_joint";
    case FrameStatus::kStampNotIncreasing: return "stamp_not_increasing";
    case FrameStatus::kTooManyBodies: return "too_many_bodies";
  }
  return "unknown";
}

IntentEstimator::IntentEstimator(std::shared_ptr<const intent::IntentModel> model, IntentEstimatorParams params)
    : model_(std::move(model)), params_(params) {
  if (!model_) throw std::invalid_argument("IntentEstimator: no model");
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (const std::string why = model_->config.Validate(); !why.empty()) {
    throw std::invalid_argument("IntentEstimator: invalid model configuration: " + why);
  }
  const auto& names = joint_names();
  for (std::size_t j = 0; j < names.size(); ++j) joint_index_[names[j]] = static_cast<int>(j);
  span_ = (model_->config.window - 1) / model_->config.rate;
  scratch_.resize(3 * static_cast<Eigen::Index>(names.size()));
  seen_.resize(names.size());
  window_.resize(model_->config.window, scratch_.size());
  cell_scales_ = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(names.size()));
}

int IntentEstimator::buffered_frames(std::uint32_t body_id) const {
  const auto it = bodies_.find(body_id);
  return it == bodies_.end() ? 0 : static_cast<int>(it->second.stamps.size());
}

FrameResult IntentEstimator::Update(const SkeletonFrame& frame, collision::JointMixture* out) {
  if (!std::isfinite(frame.stamp)) return {FrameStatus::kStampNotIncreasing, "stamp is not finite"};
  // Model joints by name; joints the model does not use are ignored.
  std::fill(seen_.begin(), seen_.end(), 0);
  for (const JointObservation& o : frame.joints) {
    const auto it = joint_index_.find(o.name);
    if (it == joint_index_.end()) continue;
    const int j = it->second;
    if (seen_[j]++ > 0) return {FrameStatus::kDuplicateJoint, "joint '" + o.name + "' appears twice"};
    if (!intent::JointDetected(o.position.transpose())) {
      return {FrameStatus::kMissingJoint, "joint '" + o.name + "' not detected (non-finite or exactly 0,0,0)"};
    }
    scratch_.segment<3>(3 * j) = o.position;
  }
  std::string missing;
  for (std::size_t j = 0; j < seen_.size(); ++j) {
    if (seen_[j] == 0) missing += (missing.empty() ? "" : ", ") + joint_names()[j];
  }
  if (!missing.empty()) return {FrameStatus::kMissingJoint, "model joints missing from the frame: " + missing};

  auto it = bodies_.find(frame.body_id);
  if (it == bodies_.end()) {
    DropStale(frame.stamp);
    if (static_cast<int>(bodies_.size()) >= params_.max_bodies) {
      return {FrameStatus::kTooManyBodies, "already tracking " + std::to_string(bodies_.size()) +
                                               " bodies (max_bodies); body " + std::to_string(frame.body_id) +
                                               " ignored"};
    }
    it = bodies_.emplace(frame.body_id, Body(*model_, params_.CoverageParams())).first;
    it->second.coverage.Reset(cell_scales_);
  }
  Body& body = it->second;
  if (!body.stamps.empty()) {
    const double last = body.stamps.back();
    if (!(frame.stamp > last)) {
      return {FrameStatus::kStampNotIncreasing, "stamp " + std::to_string(frame.stamp) + " s is not after body " +
                                                    std::to_string(frame.body_id) + "'s previous frame at " +
                                                    std::to_string(last) + " s"};
    }
    if (frame.stamp - last > params_.max_gap) {  // tracking gap: start over
      body.stamps.clear();
      body.positions.clear();
      body.belief.Reset();
      body.coverage.Reset(cell_scales_);
    }
  }
  body.stamps.push_back(frame.stamp);
  body.positions.push_back(scratch_);
  // Keep one frame at or before the oldest grid time (for interpolation).
  while (body.stamps.size() >= 2 && body.stamps[1] <= frame.stamp - span_) {
    body.stamps.pop_front();
    body.positions.pop_front();
  }
  BuildWindow(body);
  intent::PredictIntent(*model_, window_, out);
  window_probabilities_ = Eigen::Map<const Eigen::VectorXd>(out->probabilities.data(), out->num_actions());
  body.belief.UpdateWithWindow(window_probabilities_, window_, model_->config.window, frame.stamp);
  for (int c = 0; c < out->num_actions(); ++c) out->probabilities[static_cast<std::size_t>(c)] = body.belief.probabilities()(c);
  // Score the body's earlier forecasts that mature now, then calibrate this one.
  body.coverage.Observe(frame.stamp, scratch_);
  if (params_.coverage_carry_over) cell_scales_ = body.coverage.variance_scales();
  body.coverage.Apply(out);
  body.coverage.Record(frame.stamp, *out);
  DropStale(frame.stamp);
  return {};
}

void IntentEstimator::BuildWindow(const Body& body) {
  const int T = model_->config.window;
  const double dt = 1.0 / model_->config.rate;
  const double newest = body.stamps.back();
  const double oldest = body.stamps.front();
  // Grid rows at newest - (T - 1 - i) dt; rows before the first frame are
  // left out (the library pads the window at the front).
  int first = 0;
  while (first < T - 1 && newest - (T - 1 - first) * dt < oldest - 1e-9) ++first;
  const int rows = T - first;
  window_.resize(rows, scratch_.size());
  std::size_t seg = 0;  // interpolate between frames seg and seg + 1
  for (int r = 0; r < rows; ++r) {
    const double g = newest - (rows - 1 - r) * dt;
    while (seg + 1 < body.stamps.size() && body.stamps[seg + 1] < g) ++seg;
    if (seg + 1 >= body.stamps.size() || g <= body.stamps[seg]) {
      window_.row(r) = body.positions[seg].transpose();
      continue;
    }
    const double t0 = body.stamps[seg], t1 = body.stamps[seg + 1];
    const double u = (g - t0) / (t1 - t0);
    window_.row(r) = ((1.0 - u) * body.positions[seg] + u * body.positions[seg + 1]).transpose();
  }
}

int IntentEstimator::DropStale(double now) {
  int dropped = 0;
  for (auto it = bodies_.begin(); it != bodies_.end();) {
    if (it->second.stamps.empty() || it->second.stamps.back() < now - params_.body_timeout) {
      it = bodies_.erase(it);
      ++dropped;
    } else {
      ++it;
    }
  }
  return dropped;
}

}  // namespace iplan::intent_service

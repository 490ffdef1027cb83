#include "services/perception/core/skeleton_replay.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>

namespace iplan::perception {

std::string SkeletonReplayParams::Validate() const {
  if (file.empty()) return "file must name a skeleton CSV file";
  if (!(rate > 0) || !std::isfinite(rate)) return "rate must be > 0, got " + std::to_string(rate);
  if (!(pause > 0) || !std::isfinite(pause)) return "pause must be > 0 s, got " + std::to_string(pause);
  if (!(start_delay >= 0) || !std::isfinite(start_delay)) {
    return "start_delay must be >= 0 s, got " + std::to_string(start_delay);
  }
  if (!X_WS.matrix().allFinite()) return "transform must be finite";
  return "";
}

Eigen::Isometry3d TransformFromTranslationYaw(const Eigen::Vector3d& p_WS, double yaw) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = p_WS;
  return X;
}

std::string TransformFromMatrix(const std::vector<double>& m, Eigen::Isometry3d* X) {
  if (m.size() != 16) return "must have 16 numbers (4x4 row-major), got " + std::to_string(m.size());
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) M(r, c) = m[static_cast<std::size_t>(4 * r + c)];
  }
  if (!M.allFinite()) return "must be finite";
  if ((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) return "last row must be 0 0 0 1";
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if ((R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
      std::abs(R.determinant() - 1.0) > 1e-6) {
    return "upper-left 3x3 must be a rotation (orthonormal, determinant 1)";
  }
  X->matrix() = M;
  return "";
}

namespace {
intent::SkeletonDataset LoadValid(const SkeletonReplayParams& params) {
  if (const std::string why = params.Validate(); !why.empty()) throw std::invalid_argument(why);
  return intent::LoadSkeletonCsv(params.file);
}
}  // namespace

SkeletonReplay::SkeletonReplay(const SkeletonReplayParams& params) : SkeletonReplay(params, LoadValid(params)) {}

SkeletonReplay::SkeletonReplay(const SkeletonReplayParams& params, intent::SkeletonDataset data)
    : params_(params), data_(std::move(data)) {
  if (const std::string why = params_.Validate(); !why.empty()) throw std::invalid_argument(why);
  if (!params_.subjects.empty()) data_ = intent::SelectSubjects(data_, params_.subjects);
  if (!params_.sequences.empty()) {
    for (const std::string& id : params_.sequences) {
      const bool found = std::any_of(data_.sequences.begin(), data_.sequences.end(),
                                     [&](const intent::SkeletonSequence& s) { return s.id == id; });
      if (!found) {
        throw std::invalid_argument("sequence '" + id + "' is not in " + params_.file +
                                    (params_.subjects.empty() ? "" : " (for the selected subjects)"));
      }
    }
    const std::set<std::string> wanted(params_.sequences.begin(), params_.sequences.end());
    std::vector<intent::SkeletonSequence> kept;
    for (auto& s : data_.sequences) {
      if (wanted.count(s.id)) kept.push_back(std::move(s));
    }
    data_.sequences = std::move(kept);
  }
  if (data_.sequences.empty()) throw std::invalid_argument(params_.file + ": no sequence to play");

  names_ = data_.joint_names;
  for (const auto& [from, to] : params_.joint_map) {
    const auto it = std::find(data_.joint_names.begin(), data_.joint_names.end(), from);
    if (it == data_.joint_names.end()) {
      throw std::invalid_argument("joint_map: joint '" + from + "' is not in " + params_.file);
    }
    if (to.empty()) throw std::invalid_argument("joint_map: empty name for joint '" + from + "'");
    names_[static_cast<std::size_t>(it - data_.joint_names.begin())] = to;
  }
  const std::set<std::string> unique(names_.begin(), names_.end());
  if (unique.size() != names_.size()) throw std::invalid_argument("joint_map: two joints get the same name");

  double t = 0.0;
  for (std::size_t s = 0; s < data_.sequences.size(); ++s) {
    const auto& seq = data_.sequences[s];
    const double t0 = seq.time.size() > 0 ? seq.time(0) : 0.0;
    for (Eigen::Index i = 0; i < seq.time.size(); ++i) {
      schedule_.push_back({t + (seq.time(i) - t0) / params_.rate, static_cast<int>(s), static_cast<int>(i)});
    }
    if (!schedule_.empty()) t = schedule_.back().play_time + params_.pause;
  }
  pass_duration_ = t;
}

bool SkeletonReplay::finished() const { return !params_.loop && cursor_ >= schedule_.size(); }

bool SkeletonReplay::Next(double now, ReplayFrame* out) {
  while (!finished()) {
    const Entry& e = schedule_[cursor_];
    const double play_time = params_.start_delay + pass_ * pass_duration_ + e.play_time;
    if (play_time > now) return false;
    const auto& seq = data_.sequences[static_cast<std::size_t>(e.sequence)];
    out->play_time = play_time;
    out->body_id = static_cast<std::uint32_t>(1 + pass_ * num_sequences() + e.sequence);
    out->sequence_id = seq.id;
    out->action = seq.action;
    out->joints.clear();
    for (std::size_t j = 0; j < names_.size(); ++j) {
      const Eigen::RowVectorXd p_S = seq.positions.row(e.row).segment(3 * static_cast<Eigen::Index>(j), 3);
      if (!intent::JointDetected(p_S)) continue;
      out->joints.push_back({names_[j], params_.X_WS * Eigen::Vector3d(p_S(0), p_S(1), p_S(2)), 0.0});
    }
    if (++cursor_ == schedule_.size() && params_.loop) {
      cursor_ = 0;
      ++pass_;
    }
    if (!out->joints.empty()) return true;
  }
  return false;
}

}  // namespace iplan::perception

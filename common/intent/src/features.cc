#include "iplan/intent/features.h"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace iplan::intent {
namespace {

int IndexOf(const std::vector<std::string>& names, const std::string& n) {
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == n) return static_cast<int>(i);
  }
  return -1;
}

bool Has(const std::vector<std::string>& names, const std::string& n) {
  return IndexOf(names, n) >= 0;
}

std::string Join(const std::vector<std::string>& names) {
  std::string s = "[";
  for (size_t i = 0; i < names.size(); ++i) s += (i ? "," : "") + names[i];
  return s + "]";
}

}  // namespace

std::string JointConfig::Validate() const {
  if (joints.empty()) return "joint list is empty";
  std::set<std::string> unique;
  for (const std::string& j : joints) {
    if (j.empty()) return "a joint name is empty";
    if (!unique.insert(j).second) return "joint '" + j + "' listed twice";
  }
  std::set<std::string> torso_unique;
  for (const std::string& t : torso) {
    if (!Has(joints, t)) {
      return "torso joint '" + t + "' is not a model joint (joints: " + Join(joints) + ")";
    }
    if (!torso_unique.insert(t).second) return "torso joint '" + t + "' listed twice";
  }
  std::set<std::string> hand_unique;
  for (const std::string& h : hands) {
    if (!Has(joints, h)) {
      return "hand joint '" + h + "' is not a model joint (joints: " + Join(joints) + ")";
    }
    if (!hand_unique.insert(h).second) return "hand joint '" + h + "' listed twice";
  }
  for (const Eigen::Vector3d& o : objects) {
    if (!o.allFinite()) return "task object position is not finite";
  }
  return "";
}

JointConfig DefaultJointConfig(const std::vector<std::string>& available) {
  return ResolveJointConfig(available, JointSelection{});
}

JointConfig ResolveJointConfig(const std::vector<std::string>& available,
                               const JointSelection& selection) {
  JointConfig c;
  // The first of `aliases` found in `names`, or "".
  auto pick = [](const std::vector<std::string>& names,
                 std::initializer_list<const char*> aliases) -> std::string {
    for (const char* a : aliases) {
      if (Has(names, a)) return a;
    }
    return "";
  };
  if (selection.joints.has_value()) {
    for (const std::string& j : *selection.joints) {
      if (!Has(available, j)) {
        throw std::invalid_argument("joint '" + j + "' is not in the data (data joints: " +
                                    Join(available) + ")");
      }
    }
    c.joints = *selection.joints;
  } else {
    for (const std::string& j :
         {pick(available, {"head"}), pick(available, {"neck", "shoulder_center"}),
          pick(available, {"torso", "spine"}), pick(available, {"shoulder_l"}),
          pick(available, {"elbow_l"}), pick(available, {"hand_l", "wrist_l"}),
          pick(available, {"shoulder_r"}), pick(available, {"elbow_r"}),
          pick(available, {"hand_r", "wrist_r"})}) {
      if (!j.empty()) c.joints.push_back(j);
    }
    // Not an upper body by these names (a wrist tracker, a tracker with
    // names of its own): every joint the data has, in its order.
    if (c.joints.size() < 2) c.joints = available;
    if (c.joints.empty()) throw std::invalid_argument("the data has no joints");
  }
  if (selection.torso.has_value()) {
    c.torso = *selection.torso;
  } else if (const std::string torso = pick(c.joints, {"torso", "spine"}); !torso.empty()) {
    c.torso = {torso};
  } else if (Has(c.joints, "shoulder_l") && Has(c.joints, "shoulder_r")) {
    c.torso = {"shoulder_l", "shoulder_r"};
  } else {
    // No torso by name: the mean of the model joints (for one joint, the
    // joint itself: the features are its motion, not where it is).
    c.torso = c.joints;
  }
  if (selection.hands.has_value()) {
    c.hands = *selection.hands;
  } else {
    for (const std::string& h : {pick(c.joints, {"hand_l", "wrist_l"}),
                                 pick(c.joints, {"hand_r", "wrist_r"})}) {
      if (!h.empty()) c.hands.push_back(h);
    }
  }
  const std::string error = c.Validate();
  if (!error.empty()) throw std::invalid_argument("JointConfig: " + error);
  return c;
}

FeatureLayout::FeatureLayout(const JointConfig& config, const FrameFeatureOptions& options)
    : options_(options) {
  const std::string error = config.Validate();
  if (!error.empty()) throw std::invalid_argument("JointConfig: " + error);
  num_joints_ = static_cast<int>(config.joints.size());
  for (const std::string& t : config.torso) torso_index_.push_back(IndexOf(config.joints, t));
  for (const std::string& h : config.hands) hand_index_.push_back(IndexOf(config.joints, h));
  objects_ = config.objects;
  shoulder_l_ = IndexOf(config.joints, "shoulder_l");
  shoulder_r_ = IndexOf(config.joints, "shoulder_r");
  mirror_partner_.resize(num_joints_);
  for (int j = 0; j < num_joints_; ++j) {
    const std::string& n = config.joints[j];
    mirror_partner_[j] = j;
    if (n.size() < 2 || n[n.size() - 2] != '_' || (n.back() != 'l' && n.back() != 'r')) continue;
    const int partner = IndexOf(config.joints, n.substr(0, n.size() - 1) + (n.back() == 'l' ? "r" : "l"));
    if (partner >= 0) mirror_partner_[j] = partner;
  }
  if (objects_.empty()) {
    for (const char* base : {"shoulder", "hip", "elbow", "wrist", "hand"}) {
      const int l = IndexOf(config.joints, std::string(base) + "_l");
      const int r = IndexOf(config.joints, std::string(base) + "_r");
      if (l >= 0 && r >= 0) {
        lateral_l_ = l;
        lateral_r_ = r;
        break;
      }
    }
  }
}

Eigen::MatrixXd FeatureLayout::MirroredWindow(const Eigen::MatrixXd& window) const {
  if (!CanMirror()) throw std::logic_error("FeatureLayout::MirroredWindow: the joint set has no left/right pair");
  const Eigen::Index T = window.rows();
  Eigen::Vector3d lateral = Eigen::Vector3d::Zero(), centre = Eigen::Vector3d::Zero();
  for (Eigen::Index s = 0; s < T; ++s) {
    lateral += (window.block<1, 3>(s, 3 * lateral_l_) - window.block<1, 3>(s, 3 * lateral_r_)).transpose();
    for (int j = 0; j < num_joints_; ++j) centre += window.block<1, 3>(s, 3 * j).transpose();
  }
  centre /= static_cast<double>(T * num_joints_);
  Eigen::MatrixXd out(T, window.cols());
  if (!(lateral.norm() > 1e-9)) return window;  // the pair coincides: no side to mirror
  const Eigen::Vector3d n = lateral.normalized();
  for (Eigen::Index s = 0; s < T; ++s) {
    for (int j = 0; j < num_joints_; ++j) {
      const Eigen::Vector3d p = window.block<1, 3>(s, 3 * j).transpose();
      out.block<1, 3>(s, 3 * mirror_partner_[j]) = (p - 2.0 * (p - centre).dot(n) * n).transpose();
    }
  }
  return out;
}

Eigen::Vector3d FeatureLayout::Torso(
    const Eigen::Ref<const Eigen::RowVectorXd>& frame) const {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  if (torso_index_.empty()) return p;  // no torso: the origin of W
  for (int t : torso_index_) p += frame.segment<3>(3 * t).transpose();
  return p / static_cast<double>(torso_index_.size());
}

Eigen::MatrixXd FeatureLayout::FrameFeatures(const Eigen::MatrixXd& window) const {
  const int T = static_cast<int>(window.rows());
  const int J = num_joints_;
  Eigen::MatrixXd f(T, frame_feature_size());
  const Eigen::Vector3d torso_now = Torso(window.row(T - 1));
  double scale = 1.0;
  if (options_.normalise_body_size && shoulder_l_ >= 0 && shoulder_r_ >= 0) {
    double width = 0.0;
    for (int s = 0; s < T; ++s) {
      width += (window.block<1, 3>(s, 3 * shoulder_l_) - window.block<1, 3>(s, 3 * shoulder_r_)).norm();
    }
    width /= T;
    if (width > 1e-3) scale = 0.35 / width;
  }
  for (int s = 0; s < T; ++s) {
    const Eigen::Vector3d torso = Torso(window.row(s));
    for (int j = 0; j < J; ++j) {
      f.block<1, 3>(s, 3 * j) = scale * (window.block<1, 3>(s, 3 * j) - torso.transpose());
    }
    f.block<1, 3>(s, 3 * J) =
        (options_.torso_motion_weight * scale) * (torso - torso_now).transpose();
    int c = 3 * J + 3;
    for (int h : hand_index_) {
      for (const Eigen::Vector3d& o : objects_) {
        f(s, c++) = (window.block<1, 3>(s, 3 * h).transpose() - o).norm();
      }
    }
  }
  return f;
}

Eigen::VectorXd FeatureLayout::ForecastInput(const Eigen::MatrixXd& window,
                                             double rate,
                                             int velocity_frames, int history_samples) const {
  const int T = static_cast<int>(window.rows());
  const int J = num_joints_;
  const int k = std::max(1, std::min(velocity_frames, T - 1));
  const int now = T - 1;
  const int past = std::max(0, now - k);
  const double dt = (now - past) > 0 ? (now - past) / rate : 1.0 / rate;
  Eigen::VectorXd x(forecast_input_size(history_samples));
  const Eigen::Vector3d torso_now = Torso(window.row(now));
  const Eigen::Vector3d torso_past = Torso(window.row(past));
  const Eigen::Vector3d torso_first = Torso(window.row(0));
  for (int j = 0; j < J; ++j) {
    const Eigen::Vector3d rel_now =
        window.block<1, 3>(now, 3 * j).transpose() - torso_now;
    const Eigen::Vector3d rel_past =
        window.block<1, 3>(past, 3 * j).transpose() - torso_past;
    x.segment<3>(3 * j) = rel_now;
    x.segment<3>(3 * J + 3 * j) = (rel_now - rel_past) / dt;
  }
  x.segment<3>(6 * J) = (torso_now - torso_past) / dt;
  x.segment<3>(6 * J + 3) = torso_now - torso_first;
  int c = 6 * J + 6;
  for (int h : hand_index_) {
    for (const Eigen::Vector3d& o : objects_) {
      x(c++) = (window.block<1, 3>(now, 3 * h).transpose() - o).norm();
    }
  }
  for (int l = 1; l <= history_samples; ++l) {
    const int back = std::max(0, now - (l * (T - 1)) / history_samples);
    for (int j = 0; j < J; ++j, c += 3) {
      x.segment<3>(c) = (window.block<1, 3>(now, 3 * j) - window.block<1, 3>(back, 3 * j)).transpose();
    }
  }
  return x;
}

Eigen::MatrixXd WindowEndingAt(const Eigen::MatrixXd& positions, int end, int T) {
  if (T < 1 || end < 0 || end >= positions.rows()) {
    throw std::out_of_range("WindowEndingAt: end " + std::to_string(end) +
                            " outside [0, " + std::to_string(positions.rows()) +
                            ") or T " + std::to_string(T) + " < 1");
  }
  Eigen::MatrixXd w(T, positions.cols());
  for (int s = 0; s < T; ++s) {
    const int r = std::max(0, end - (T - 1) + s);
    w.row(s) = positions.row(r);
  }
  return w;
}

}  // namespace iplan::intent

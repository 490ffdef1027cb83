#include "iplan/collision/human_model.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include "iplan/core/params.h"

#include "check.h"

namespace iplan::collision {
namespace {

int IndexOf(const std::vector<std::string>& v, const std::string& s) {
  auto it = std::find(v.begin(), v.end(), s);
  return it == v.end() ? -1 : static_cast<int>(it - v.begin());
}

}  // namespace

std::string HumanBodyParams::Validate() const {
  std::ostringstream msg;
  if (joints.empty()) return "no joints";
  std::set<std::string> seen;
  for (const std::string& j : joints) {
    if (!seen.insert(j).second) return "joint '" + j + "' listed twice";
  }
  if (segments.empty()) return "no segments";
  for (size_t i = 0; i < segments.size(); ++i) {
    const HumanSegmentParams& s = segments[i];
    const std::string where = "segment " + std::to_string(i) + " ('" + s.name + "')";
    if (IndexOf(joints, s.joint_a) < 0) return where + ": unknown joint '" + s.joint_a + "'";
    if (IndexOf(joints, s.joint_b) < 0) return where + ": unknown joint '" + s.joint_b + "'";
    if (s.count < 1) {
      msg << where << ": count = " << s.count << " must be >= 1";
      return msg.str();
    }
    if (!(s.radius > 0.0) || !std::isfinite(s.radius)) {
      msg << where << ": radius = " << s.radius << " must be positive";
      return msg.str();
    }
    if (!s.u.empty() && static_cast<int>(s.u.size()) != s.count) {
      msg << where << ": " << s.u.size() << " values of u for count = " << s.count;
      return msg.str();
    }
    for (double u : s.u) {
      if (!(u >= 0.0 && u <= 1.0)) {
        msg << where << ": u = " << u << " must be in [0, 1]";
        return msg.str();
      }
    }
  }
  return {};
}

HumanBodyParams HumanBodyParams::DefaultUpperBody() {
  HumanBodyParams p;
  // Joint names follow the skeleton convention of perception and the
  // recorded data: _l / _r suffixes.
  p.joints = {"head", "neck", "torso", "shoulder_l", "elbow_l", "hand_l", "shoulder_r", "elbow_r", "hand_r"};
  p.segments = {
      {"head", "head", "neck", 2, 0.12, {}},
      {"trunk", "neck", "torso", 2, 0.17, {}},
      {"shoulder_left", "neck", "shoulder_l", 2, 0.08, {}},
      {"upper_arm_left", "shoulder_l", "elbow_l", 2, 0.07, {}},
      {"forearm_left", "elbow_l", "hand_l", 2, 0.06, {0.25, 1.0}},
      {"shoulder_right", "neck", "shoulder_r", 2, 0.08, {}},
      {"upper_arm_right", "shoulder_r", "elbow_r", 2, 0.07, {}},
      {"forearm_right", "elbow_r", "hand_r", 2, 0.06, {0.25, 1.0}},
  };
  return p;
}

HumanBodyParams LoadHumanBodyParams(const std::string& path) {
  return core::LoadParamsFile<HumanBodyParams>(path, {}, core::ConfigSection::EmptyFile::kError);
}

HumanBodyModel::HumanBodyModel(HumanBodyParams params) : params_(std::move(params)) {
  if (const std::string why = params_.Validate(); !why.empty()) {
    throw std::invalid_argument("HumanBodyParams: " + why);
  }
  for (size_t i = 0; i < params_.segments.size(); ++i) {
    const HumanSegmentParams& s = params_.segments[i];
    for (int k = 0; k < s.count; ++k) {
      const double u = s.u.empty() ? (k + 0.5) / s.count : s.u[k];
      spheres_.push_back({static_cast<int>(i), IndexOf(params_.joints, s.joint_a),
                          IndexOf(params_.joints, s.joint_b), u, s.radius});
    }
  }
}

std::vector<double> HumanBodyModel::Radii() const {
  std::vector<double> r;
  for (const SphereDef& s : spheres_) r.push_back(s.radius);
  return r;
}

std::vector<int> HumanBodyModel::Segments() const {
  std::vector<int> r;
  for (const SphereDef& s : spheres_) r.push_back(s.segment);
  return r;
}

void HumanBodyModel::CalcSphereGaussian(int sphere, const Eigen::Matrix3Xd& joint_means,
                                        const std::vector<Eigen::Matrix3d>& joint_covs,
                                        Eigen::Vector3d* mean, Eigen::Matrix3d* cov) const {
  IPLAN_COLLISION_DEMAND(joint_means.cols() == num_joints());
  IPLAN_COLLISION_DEMAND(static_cast<int>(joint_covs.size()) == num_joints());
  const SphereDef& s = spheres_[sphere];
  const double a = 1.0 - s.u;
  const double b = s.u;
  *mean = a * joint_means.col(s.joint_a) + b * joint_means.col(s.joint_b);
  *cov = (a * a) * joint_covs[s.joint_a] + (b * b) * joint_covs[s.joint_b];
}

bool HumanBodyModel::FillPrediction(const Eigen::Matrix3Xd& joint_means,
                                    const std::vector<Eigen::Matrix3d>& joint_covs, int action,
                                    int step, HumanPrediction* prediction) const {
  IPLAN_COLLISION_DEMAND(prediction->num_spheres() == num_spheres());
  bool ok = true;
  Eigen::Vector3d mean;
  Eigen::Matrix3d cov;
  for (int i = 0; i < num_spheres(); ++i) {
    CalcSphereGaussian(i, joint_means, joint_covs, &mean, &cov);
    ok = prediction->SetSphere(action, step, i, mean, cov) && ok;
  }
  return ok;
}

HumanPrediction HumanBodyModel::MakePrediction(int num_actions, int num_steps) const {
  return HumanPrediction(num_actions, num_steps, Radii(), Segments());
}

}  // namespace iplan::collision

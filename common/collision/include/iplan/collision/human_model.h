// Human body as spheres along skeleton segments (METHOD.md section 4).
//
// A sphere on the segment between joints a and b has centre
// c = (1 - u) z_a + u z_b, 0 <= u <= 1. With independent joint Gaussians
// z_i ~ N(mu_i, Sigma_i) (world frame W, m, m^2):
//   c ~ N((1 - u) mu_a + u mu_b, (1 - u)^2 Sigma_a + u^2 Sigma_b).
#pragma once

#include <string>
#include <vector>

#include "iplan/core/name_value.h"

#include <Eigen/Core>

#include "iplan/collision/trajectory_bound.h"

namespace iplan::collision {

/// One skeleton segment and its spheres.
struct HumanSegmentParams {
  std::string name;      ///< e.g. "forearm_left"
  std::string joint_a;   ///< joint name at u = 0
  std::string joint_b;   ///< joint name at u = 1
  int count = 2;         ///< number of spheres, >= 1
  double radius = 0.08;  ///< sphere radius (m), > 0
  /// Positions u in [0, 1] of the spheres; empty = evenly at (k + 0.5)/count.
  std::vector<double> u;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP_REQUIRED(name, "segment name"));
    a->Visit(IPLAN_NVP_REQUIRED(joint_a, "joint at u = 0"));
    a->Visit(IPLAN_NVP_REQUIRED(joint_b, "joint at u = 1"));
    a->Visit(IPLAN_NVP_REQUIRED(count, "number of spheres, >= 1"));
    a->Visit(IPLAN_NVP_REQUIRED(radius, "m; sphere radius, > 0"));
    a->Visit(IPLAN_NVP(u, "positions of the spheres in [0, 1], count of them; [] = evenly"));
  }
};

/// The body: joint names (the order of the skeleton input) and segments.
struct HumanBodyParams {
  std::vector<std::string> joints;
  std::vector<HumanSegmentParams> segments;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP_REQUIRED(joints, "joint names, in the order of the skeleton input"));
    a->Visit(IPLAN_NVP_REQUIRED(segments, "the body's segments"));
  }

  /// Empty string when valid, else the reason naming the offending entry.
  std::string Validate() const;

  /// The 9-joint upper body (head, neck, torso, shoulder/elbow/hand left and
  /// right), 8 segments with 2 spheres each = 16 spheres. Radii (m) within the
  /// ranges of METHOD 4: head 0.12, torso 0.17, shoulder girdle 0.08, upper
  /// arm 0.07, forearm 0.06. Spheres sit at u = 0.25 and 0.75 of each segment,
  /// except on the forearms (u = 0.25 and 1) so that each hand is a centre.
  static HumanBodyParams DefaultUpperBody();
};

/// Loads HumanBodyParams from YAML (keys: joints: [names], segments: [{name,
/// joint_a, joint_b, count, radius, u}], as Serialize declares them) with
/// core::LoadParamsFile: unknown keys, wrong types, missing keys, an empty
/// file and Validate() failures are errors.
/// @throws std::runtime_error naming the file, key and value.
HumanBodyParams LoadHumanBodyParams(const std::string& path);

/// Immutable sphere model of the body. Const methods are thread-safe.
class HumanBodyModel {
 public:
  struct SphereDef {
    int segment;     ///< index into params().segments
    int joint_a;     ///< index into params().joints
    int joint_b;
    double u;
    double radius;   ///< m
  };

  /// @throws std::invalid_argument with the reason if params are invalid.
  explicit HumanBodyModel(HumanBodyParams params);

  const HumanBodyParams& params() const { return params_; }
  int num_joints() const { return static_cast<int>(params_.joints.size()); }
  int num_spheres() const { return static_cast<int>(spheres_.size()); }
  const std::vector<SphereDef>& spheres() const { return spheres_; }
  /// Sphere radii (m) and segment ids, in sphere order (allocates).
  std::vector<double> Radii() const;
  std::vector<int> Segments() const;

  /// Centre of sphere `sphere`, (1 - u) p_a + u p_b, from the joints'
  /// positions (3 x num_joints, m, W); with joint velocities (m/s) instead
  /// it gives the centre's velocity (the map is linear). Does not allocate.
  Eigen::Vector3d SphereCentre(int sphere, const Eigen::Matrix3Xd& joints) const {
    const SphereDef& d = spheres_[static_cast<std::size_t>(sphere)];
    return (1 - d.u) * joints.col(d.joint_a) + d.u * joints.col(d.joint_b);
  }

  /// Gaussian of sphere `sphere`'s centre from the joint Gaussians.
  /// joint_means: 3 x num_joints (m, W); joint_covs: num_joints matrices
  /// (m^2). Does not allocate.
  void CalcSphereGaussian(int sphere, const Eigen::Matrix3Xd& joint_means,
                          const std::vector<Eigen::Matrix3d>& joint_covs,
                          Eigen::Vector3d* mean, Eigen::Matrix3d* cov) const;

  /// Fills all spheres of (action, step) in `prediction` (which must have
  /// num_spheres() spheres). Returns false if some sphere covariance is not
  /// positive definite (those spheres keep their previous value). Does not
  /// allocate. Call prediction->UpdateSummaries() when all are filled.
  bool FillPrediction(const Eigen::Matrix3Xd& joint_means,
                      const std::vector<Eigen::Matrix3d>& joint_covs, int action, int step,
                      HumanPrediction* prediction) const;

  /// A prediction sized for this body (allocates).
  HumanPrediction MakePrediction(int num_actions, int num_steps) const;

 private:
  HumanBodyParams params_;
  std::vector<SphereDef> spheres_;
};

}  // namespace iplan::collision

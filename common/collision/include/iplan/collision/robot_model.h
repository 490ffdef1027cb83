// Kinematic model of a robot arm with collision spheres, loaded from a URDF
// file (urdfdom, kept out of this header) or from a modified-DH YAML file
// (config/robots/panda.yaml). Split as in Pinocchio: an immutable RobotModel
// and a preallocated RobotData; forward kinematics does not allocate.
//
// Frames: W is the world (= the root link frame), L a link frame. Poses are
// X_AB (pose of B in A), positions p_AQ (position of Q in A). SI units: m,
// rad, rad/s, rad/s^2, rad/s^3 (m/... for prismatic joints).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "iplan/collision/mesh_cover.h"
#include "iplan/collision/sphere_cover.h"
#include "iplan/core/name_value.h"

namespace iplan::collision {

enum class JointType { kFixed, kRevolute, kPrismatic };

/// Limits of one joint. Position limits are +-infinity for continuous joints.
struct JointLimits {
  double lower = 0.0;         ///< rad or m
  double upper = 0.0;         ///< rad or m
  double velocity = 0.0;      ///< rad/s or m/s
  double acceleration = 0.0;  ///< rad/s^2 or m/s^2
  double jerk = 0.0;          ///< rad/s^3 or m/s^3
};

/// A joint: the child link's frame is X_PC(q) = X_PJ * Motion(axis, q), with
/// X_PJ the joint origin in the parent link frame and the axis (unit) in the
/// joint frame; Motion is a rotation by q about the axis (revolute) or a
/// translation by q along it (prismatic).
struct Joint {
  std::string name;
  JointType type = JointType::kFixed;
  int parent_link = -1;
  int child_link = -1;
  Eigen::Isometry3d X_PJ = Eigen::Isometry3d::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  /// Index into q, or -1 for fixed and mimic joints.
  int q_index = -1;
  /// Mimic joints: value = multiplier * q[mimic_q_index] + offset.
  int mimic_q_index = -1;
  double mimic_multiplier = 1.0;
  double mimic_offset = 0.0;
  JointLimits limits;
};

/// A collision sphere rigidly attached to a link (centre p_LS in the link frame).
struct CollisionSphere {
  int link = -1;
  Eigen::Vector3d p_LS = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

/// The over-approximation of one collision shape of the source file.
struct ShapeCoverEntry {
  std::string link;
  CoverReport cover;
  /// Mesh shapes: the mesh file (resolved path) and its cover's report.
  std::string mesh_file;
  std::optional<MeshCoverReport> mesh;
};

/// Immutable robot description. Links are ordered parents first (link 0 is
/// the root); joints[j] moves link joints[j].child_link and joints are
/// ordered like their child links, so one forward pass computes all poses.
struct RobotModel {
  std::string name;
  std::vector<std::string> link_names;
  /// Index of the joint whose child is each link; -1 for the root.
  std::vector<int> link_parent_joint;
  std::vector<Joint> joints;
  /// Number of configuration variables (actuated, non-mimic, unlocked joints).
  int nq = 0;
  /// Joint index for each configuration variable (size nq).
  std::vector<int> q_joints;
  std::vector<CollisionSphere> spheres;
  /// The link whose pose a pose goal gives (the tool), when the robot's file
  /// says (a URDF overlay's tool_link); empty: not said (planning::
  /// AdaptLinksToRobot then takes the last link).
  std::string tool_link;
  /// One entry per collision shape of the source file.
  std::vector<ShapeCoverEntry> cover_report;

  /// Index of the link / joint with this name; -1 if there is none (linear
  /// search; not for hot loops).
  int FindLink(const std::string& name) const;
  int FindJoint(const std::string& name) const;
  /// Joint names of the configuration variables, in q order (size nq):
  /// the names joint states and trajectories carry. Allocates.
  std::vector<std::string> JointNames() const;
  /// Lower/upper position limits of the configuration variables (size nq).
  Eigen::VectorXd LowerLimits() const;
  Eigen::VectorXd UpperLimits() const;
};

/// Preallocated results of forward kinematics.
struct RobotData {
  /// Allocates for `model`.
  explicit RobotData(const RobotModel& model);
  /// X_WL for every link (size = number of links).
  std::vector<Eigen::Isometry3d> X_WL;
  /// Sphere centres p_WS in W, 3 x number of spheres.
  Eigen::Matrix3Xd p_WS;
};

/// Forward kinematics: fills data->X_WL and data->p_WS for configuration q
/// (size model.nq; rad / m). Does not check limits. Aborts if sizes mismatch
/// (caller contract). Thread-safe for distinct data; does not allocate.
void CalcForwardKinematics(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                           RobotData* data);

/// Why the configuration `q` (model order, size model.nq; rad / m) is outside
/// the position limits by more than `tolerance` (rad / m, >= 0), e.g. "joint
/// 'panda_joint4' at 100 rad is outside its limits [-3.0718, -0.0698] rad by
/// more than 0.05"; nullopt when every joint is within. For measured states:
/// the tolerance absorbs encoder noise and a stop's overshoot, a value beyond
/// it means a wrong or corrupted state. Non-finite values and a size other
/// than nq are reported too. Continuous joints are unbounded. Allocates only
/// for the returned text.
std::optional<std::string> CheckJointPositions(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                               double tolerance);

/// Why the joint velocities `qd` (model order, size model.nq; rad/s / m/s)
/// exceed `tolerance_factor` (>= 1) times the velocity limit in magnitude,
/// e.g. "joint 'panda_joint1' at 5 rad/s is beyond 1.2 x its limit 2.175
/// rad/s"; nullopt when every joint is within. A joint whose model states
/// no velocity limit (not positive or infinite) is not checked. Non-finite
/// values and a size other than nq are reported. Allocates only for the
/// returned text.
std::optional<std::string> CheckJointVelocities(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& qd,
                                                double tolerance_factor);

/// Options of the loaders.
struct RobotModelOptions {
  SphereCoverParams cover;
  /// Joints held at a fixed value (rad or m), e.g. gripper fingers; they become
  /// fixed joints and leave q. Unknown names are an error.
  std::map<std::string, double> locked_joints;
  /// URDF has no acceleration or jerk limits; these are used for every joint
  /// (rad/s^2, rad/s^3 or m/s^2, m/s^3). Defaults are conservative for
  /// collaborative arms (Franka's smallest published values are 7.5 and 3750).
  double default_acceleration = 7.5;
  double default_jerk = 3750.0;
  /// Covers of <mesh> collision shapes (mesh_cover.h).
  MeshCoverParams mesh_cover;
  /// Where mesh covers are cached; nullopt: DefaultMeshCoverCacheDir(); an
  /// empty string: no cache.
  std::optional<std::string> mesh_cache_dir;
  /// Skip <mesh> collision shapes instead of covering them (they are then not
  /// covered by any sphere: unsafe unless other shapes cover them).
  bool ignore_mesh_collisions = false;
  /// Drop spheres contained in another sphere of the same link.
  bool remove_contained_spheres = true;
};

/// Loads a robot from a URDF file: the kinematic tree (revolute, continuous,
/// prismatic, fixed joints; mimic joints follow their master), limits, and
/// collision spheres covering each <collision> shape (sphere kept as is,
/// cylinder and box covered, see sphere_cover.h; meshes read and covered as
/// in mesh_cover.h, their files relative to the URDF, file:// or
/// package://NAME/... found on $ROS_PACKAGE_PATH or as a folder NAME above
/// the URDF). Visual elements are ignored.
/// @throws std::runtime_error naming the file and the problem (unreadable or
///         invalid URDF, unsupported joint type, a mesh that cannot be found
///         or read, unknown locked joint, invalid options).
/// Thread-safe (no shared state); allocates. urdfdom may print parser
/// warnings to stderr (console_bridge) before the exception.
RobotModel LoadRobotModelFromUrdf(const std::string& path, const RobotModelOptions& options = {});

/// Loads a serial arm from a YAML file in modified (Craig) Denavit-Hartenberg
/// form: X_{i-1,i} = RotX(alpha) TransX(a) RotZ(theta_offset) TransZ(d) then
/// RotZ(q_i) (revolute) / TransZ(q_i) (prismatic). Collision geometry as
/// spheres, capsules and boxes per link, covered as in sphere_cover.h. See
/// config/robots/panda.yaml for the format. Unknown keys are errors.
/// @throws std::runtime_error naming the file, the key and the value.
/// Thread-safe (no shared state); allocates.
RobotModel LoadRobotModelFromYaml(const std::string& path, const RobotModelOptions& options = {});

/// A URDF and what URDF does not say, as a small YAML file (the "overlay";
/// paths relative to it), so that a cell's configs name a URDF robot the
/// way they name a YAML one:
///   urdf: ur5e/ur5e.urdf
///   tool_link: tool0
///   locked_joints: [{name: panda_finger_joint1, value: 0.0}]
///   acceleration: 7.5   # rad/s^2 (m/s^2), every joint
///   jerk: 3750.0        # rad/s^3 (m/s^3), every joint
struct UrdfOverlay {
  struct LockedJoint {
    std::string name;
    double value = 0.0;  ///< rad or m
    template <class Archive>
    void Serialize(Archive* a) {
      a->Visit(IPLAN_NVP_REQUIRED(name, "joint name in the URDF"));
      a->Visit(IPLAN_NVP(value, "rad or m, the joint's fixed value"));
    }
  };
  std::string urdf;
  std::string tool_link;
  std::vector<LockedJoint> locked_joints;
  double acceleration = RobotModelOptions{}.default_acceleration;
  double jerk = RobotModelOptions{}.default_jerk;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP_REQUIRED(urdf, "the URDF file, relative to this file"));
    a->Visit(IPLAN_NVP(tool_link, "link whose pose pose goals give (default: none said; the planner takes the last link)"));
    a->Visit(IPLAN_NVP(locked_joints, "joints held at a fixed value (e.g. gripper fingers); they leave q"));
    a->Visit(IPLAN_NVP(acceleration, "rad/s^2 (m/s^2) limit of every joint (URDF has none), > 0"));
    a->Visit(IPLAN_NVP(jerk, "rad/s^3 (m/s^3) limit of every joint (URDF has none), > 0"));
  }
  /// Empty when valid, else the reason.
  std::string Validate() const {
    if (urdf.empty()) return "urdf must name the URDF file";
    if (!(acceleration > 0)) return "acceleration must be > 0";
    if (!(jerk > 0)) return "jerk must be > 0";
    return "";
  }
};

/// Loads the robot a config names, whatever form its file has: a URDF
/// (`.urdf`, or a file that starts as XML) with `options` as given; a URDF
/// overlay (a YAML file with a top-level `urdf` key, see UrdfOverlay) whose
/// values replace those of `options`; else a modified-DH YAML file
/// (LoadRobotModelFromYaml). What every service and tool calls.
/// @throws std::runtime_error naming the file and the problem.
RobotModel LoadRobotModel(const std::string& path, const RobotModelOptions& options = {});

}  // namespace iplan::collision

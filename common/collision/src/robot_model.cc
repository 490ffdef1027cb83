#include "iplan/collision/robot_model.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include <urdf_parser/urdf_parser.h>

#include "check.h"
#include "iplan/core/params.h"
#include "robot_model_mesh.h"

namespace iplan::collision {
namespace {

constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void Fail(const std::string& path, const std::string& what) { throw std::runtime_error(path + ": " + what); }

Eigen::Isometry3d ToIsometry(const urdf::Pose& pose) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  Eigen::Quaterniond q(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z);
  X.linear() = q.normalized().toRotationMatrix();
  return X;
}

// Adds the spheres of a list (frame = link `link`) with contained ones removed.
void AddLinkSpheres(int link, std::vector<Sphere> spheres, bool remove_contained,
                    RobotModel* model) {
  if (remove_contained) RemoveContainedSpheres(&spheres);
  for (const Sphere& s : spheres) model->spheres.push_back({link, s.centre, s.radius});
}

void Finalize(const RobotModelOptions& options, const std::string& path, RobotModel* model) {
  // Locked joints become fixed at their value; then number the q variables.
  std::set<std::string> unknown;
  for (const auto& [name, value] : options.locked_joints) unknown.insert(name);
  for (Joint& j : model->joints) {
    auto it = options.locked_joints.find(j.name);
    if (it == options.locked_joints.end()) continue;
    unknown.erase(j.name);
    if (j.type == JointType::kRevolute) {
      j.X_PJ = j.X_PJ * Eigen::AngleAxisd(it->second, j.axis);
    } else if (j.type == JointType::kPrismatic) {
      j.X_PJ = j.X_PJ * Eigen::Translation3d(it->second * j.axis);
    }
    j.type = JointType::kFixed;
    j.mimic_q_index = -1;
  }
  if (!unknown.empty()) Fail(path, "locked joint '" + *unknown.begin() + "' does not exist");
  // Mimic joints were recorded with their master's joint index in
  // mimic_q_index; translate to q indices now.
  model->nq = 0;
  model->q_joints.clear();
  for (size_t j = 0; j < model->joints.size(); ++j) {
    Joint& joint = model->joints[j];
    joint.q_index = -1;
    if (joint.type != JointType::kFixed && joint.mimic_q_index < 0) {
      joint.q_index = model->nq++;
      model->q_joints.push_back(static_cast<int>(j));
    }
  }
  for (Joint& joint : model->joints) {
    if (joint.type == JointType::kFixed || joint.mimic_q_index < 0) continue;
    const Joint& master = model->joints[joint.mimic_q_index];
    if (master.q_index < 0) {
      // Master locked or itself a mimic: freeze this joint at the master's value.
      Fail(path, "mimic joint '" + joint.name + "' follows '" + master.name +
                     "', which is not a free joint (lock both or neither)");
    }
    joint.mimic_q_index = master.q_index;
  }
}

}  // namespace

int RobotModel::FindLink(const std::string& n) const {
  for (size_t i = 0; i < link_names.size(); ++i) {
    if (link_names[i] == n) return static_cast<int>(i);
  }
  return -1;
}

int RobotModel::FindJoint(const std::string& n) const {
  for (size_t i = 0; i < joints.size(); ++i) {
    if (joints[i].name == n) return static_cast<int>(i);
  }
  return -1;
}

std::vector<std::string> RobotModel::JointNames() const {
  std::vector<std::string> names;
  for (int j : q_joints) names.push_back(joints[static_cast<std::size_t>(j)].name);
  return names;
}

Eigen::VectorXd RobotModel::LowerLimits() const {
  Eigen::VectorXd v(nq);
  for (int i = 0; i < nq; ++i) v[i] = joints[q_joints[i]].limits.lower;
  return v;
}

Eigen::VectorXd RobotModel::UpperLimits() const {
  Eigen::VectorXd v(nq);
  for (int i = 0; i < nq; ++i) v[i] = joints[q_joints[i]].limits.upper;
  return v;
}

namespace {

std::string Num(double x) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%g", x);
  return buf;
}

const char* Unit(const Joint& j, bool per_second) {
  if (j.type == JointType::kPrismatic) return per_second ? "m/s" : "m";
  return per_second ? "rad/s" : "rad";
}

}  // namespace

std::optional<std::string> CheckJointPositions(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                               double tolerance) {
  if (q.size() != model.nq) {
    return std::to_string(q.size()) + " joint positions for a robot of " + std::to_string(model.nq) + " joints";
  }
  for (int i = 0; i < model.nq; ++i) {
    const Joint& j = model.joints[static_cast<std::size_t>(model.q_joints[static_cast<std::size_t>(i)])];
    const double v = q[i];
    if (!std::isfinite(v)) return "joint '" + j.name + "' at " + Num(v) + " " + Unit(j, false) + " is not finite";
    // Written so that the infinite limits of continuous joints pass.
    if (!(v >= j.limits.lower - tolerance && v <= j.limits.upper + tolerance)) {
      return "joint '" + j.name + "' at " + Num(v) + " " + Unit(j, false) + " is outside its limits [" +
             Num(j.limits.lower) + ", " + Num(j.limits.upper) + "] " + Unit(j, false) + " by more than " +
             Num(tolerance);
    }
  }
  return std::nullopt;
}

std::optional<std::string> CheckJointVelocities(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& qd,
                                                double tolerance_factor) {
  if (qd.size() != model.nq) {
    return std::to_string(qd.size()) + " joint velocities for a robot of " + std::to_string(model.nq) + " joints";
  }
  for (int i = 0; i < model.nq; ++i) {
    const Joint& j = model.joints[static_cast<std::size_t>(model.q_joints[static_cast<std::size_t>(i)])];
    const double v = qd[i];
    if (!std::isfinite(v)) return "joint '" + j.name + "' at " + Num(v) + " " + Unit(j, true) + " is not finite";
    const double limit = j.limits.velocity;
    if (!(limit > 0) || std::isinf(limit)) continue;  // no limit stated (URDF without <limit velocity>)
    if (std::abs(v) > tolerance_factor * limit) {
      return "joint '" + j.name + "' at " + Num(v) + " " + Unit(j, true) + " is beyond " + Num(tolerance_factor) +
             " x its limit " + Num(limit) + " " + Unit(j, true);
    }
  }
  return std::nullopt;
}

RobotData::RobotData(const RobotModel& model)
    : X_WL(model.link_names.size(), Eigen::Isometry3d::Identity()),
      p_WS(3, static_cast<Eigen::Index>(model.spheres.size())) {
  p_WS.setZero();
}

void CalcForwardKinematics(const RobotModel& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                           RobotData* data) {
  IPLAN_COLLISION_DEMAND(data != nullptr && q.size() == model.nq);
  IPLAN_COLLISION_DEMAND(data->X_WL.size() == model.link_names.size());
  IPLAN_COLLISION_DEMAND(data->p_WS.cols() == static_cast<Eigen::Index>(model.spheres.size()));
  data->X_WL[0].setIdentity();
  for (const Joint& j : model.joints) {
    const Eigen::Isometry3d& X_WP = data->X_WL[j.parent_link];
    Eigen::Isometry3d& X_WC = data->X_WL[j.child_link];
    double value = 0.0;
    if (j.q_index >= 0) {
      value = q[j.q_index];
    } else if (j.mimic_q_index >= 0) {
      value = j.mimic_multiplier * q[j.mimic_q_index] + j.mimic_offset;
    }
    switch (j.type) {
      case JointType::kFixed:
        X_WC = X_WP * j.X_PJ;
        break;
      case JointType::kRevolute:
        X_WC = X_WP * j.X_PJ * Eigen::AngleAxisd(value, j.axis);
        break;
      case JointType::kPrismatic:
        X_WC = X_WP * j.X_PJ * Eigen::Translation3d(value * j.axis);
        break;
    }
  }
  for (size_t s = 0; s < model.spheres.size(); ++s) {
    const CollisionSphere& cs = model.spheres[s];
    data->p_WS.col(static_cast<Eigen::Index>(s)) = data->X_WL[cs.link] * cs.p_LS;
  }
}

namespace {

// A URDF joint as ours; `mimic_master` gets the joint it mimics, if any.
Joint UrdfJoint(const std::string& path, const RobotModel& model, const urdf::Joint& uj, int child,
                const RobotModelOptions& options, std::string* mimic_master) {
  Joint j;
  j.name = uj.name;
  j.parent_link = model.FindLink(uj.parent_link_name);
  j.child_link = child;
  j.X_PJ = ToIsometry(uj.parent_to_joint_origin_transform);
  j.axis = Eigen::Vector3d(uj.axis.x, uj.axis.y, uj.axis.z);
  switch (uj.type) {
    case urdf::Joint::FIXED:
      j.type = JointType::kFixed;
      break;
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
      j.type = JointType::kRevolute;
      break;
    case urdf::Joint::PRISMATIC:
      j.type = JointType::kPrismatic;
      break;
    default:
      Fail(path, "joint '" + j.name + "' has an unsupported type (" + std::to_string(static_cast<int>(uj.type)) +
                     "); only fixed, revolute, continuous and prismatic are supported");
  }
  if (j.type == JointType::kFixed) return j;
  const double n = j.axis.norm();
  if (!(n > 0.0)) Fail(path, "joint '" + j.name + "' has a zero axis");
  j.axis /= n;
  j.limits.acceleration = options.default_acceleration;
  j.limits.jerk = options.default_jerk;
  if (uj.type == urdf::Joint::CONTINUOUS || !uj.limits) {
    j.limits.lower = -std::numeric_limits<double>::infinity();
    j.limits.upper = std::numeric_limits<double>::infinity();
  } else {
    j.limits.lower = uj.limits->lower;
    j.limits.upper = uj.limits->upper;
  }
  j.limits.velocity = uj.limits ? uj.limits->velocity : std::numeric_limits<double>::infinity();
  if (uj.mimic) {
    j.mimic_multiplier = uj.mimic->multiplier;
    j.mimic_offset = uj.mimic->offset;
    *mimic_master = uj.mimic->joint_name;
  }
  return j;
}

// The spheres covering one URDF collision shape (in the link's frame), and
// its entry of the cover report; empty for an ignored mesh.
std::vector<Sphere> CoverShape(const std::string& path, const std::string& link, const urdf::Collision& col,
                               const RobotModelOptions& options, ShapeCoverEntry* entry) {
  const Eigen::Isometry3d X_LG = ToIsometry(col.origin);
  entry->link = link;
  std::vector<Sphere> cover;
  try {
    switch (col.geometry->type) {
      case urdf::Geometry::SPHERE: {
        const double r = static_cast<const urdf::Sphere&>(*col.geometry).radius;
        if (!(r > 0.0)) Fail(path, "link '" + link + "': sphere radius " + std::to_string(r));
        cover.push_back({X_LG.translation(), r});
        entry->cover.shape = "sphere";
        entry->cover.num_spheres = 1;
        entry->cover.shape_volume = 4.0 / 3.0 * kPi * r * r * r;
        break;
      }
      case urdf::Geometry::CYLINDER: {
        const auto& c = static_cast<const urdf::Cylinder&>(*col.geometry);
        cover = CoverCylinder(c.radius, c.length, X_LG, options.cover, &entry->cover);
        break;
      }
      case urdf::Geometry::BOX: {
        const auto& b = static_cast<const urdf::Box&>(*col.geometry);
        cover = CoverBox(0.5 * Eigen::Vector3d(b.dim.x, b.dim.y, b.dim.z), X_LG, options.cover, &entry->cover);
        break;
      }
      case urdf::Geometry::MESH: {
        if (options.ignore_mesh_collisions) return {};
        const auto& m = static_cast<const urdf::Mesh&>(*col.geometry);
        return CoverUrdfMesh(path, link, m.filename, {m.scale.x, m.scale.y, m.scale.z}, X_LG, options, entry);
      }
    }
  } catch (const std::invalid_argument& e) {
    Fail(path, "link '" + link + "': " + e.what());
  }
  return cover;
}

}  // namespace

RobotModel LoadRobotModelFromUrdf(const std::string& path, const RobotModelOptions& options) {
  if (const std::string why = options.cover.Validate(); !why.empty()) Fail(path, why);
  const urdf::ModelInterfaceSharedPtr urdf = urdf::parseURDFFile(path);
  if (!urdf) Fail(path, "cannot read or parse the URDF file");
  const urdf::LinkConstSharedPtr root = urdf->getRoot();
  if (!root) Fail(path, "URDF has no root link");

  RobotModel model;
  model.name = urdf->getName();
  // Depth-first, parents before children; joint j's child is link j + 1.
  std::vector<urdf::LinkConstSharedPtr> links;
  std::function<void(const urdf::LinkConstSharedPtr&)> visit = [&](const urdf::LinkConstSharedPtr& link) {
    links.push_back(link);
    for (const urdf::LinkSharedPtr& child : link->child_links) visit(child);
  };
  visit(root);
  for (const auto& link : links) model.link_names.push_back(link->name);
  model.link_parent_joint.assign(links.size(), -1);

  std::vector<std::string> mimic_master(links.size());
  for (size_t i = 1; i < links.size(); ++i) {
    const Joint j = UrdfJoint(path, model, *links[i]->parent_joint, static_cast<int>(i), options, &mimic_master[i]);
    model.link_parent_joint[i] = static_cast<int>(model.joints.size());
    model.joints.push_back(j);
  }
  for (size_t i = 1; i < links.size(); ++i) {
    if (mimic_master[i].empty()) continue;
    Joint& j = model.joints[model.link_parent_joint[i]];
    j.mimic_q_index = model.FindJoint(mimic_master[i]);
    if (j.mimic_q_index < 0) {
      Fail(path, "mimic joint '" + j.name + "' follows unknown joint '" + mimic_master[i] + "'");
    }
  }

  // Collision shapes -> spheres.
  for (size_t i = 0; i < links.size(); ++i) {
    std::vector<Sphere> spheres;
    for (const urdf::CollisionSharedPtr& col : links[i]->collision_array) {
      if (!col || !col->geometry) continue;
      ShapeCoverEntry entry;
      const bool ignored_mesh = col->geometry->type == urdf::Geometry::MESH && options.ignore_mesh_collisions;
      const std::vector<Sphere> cover = CoverShape(path, links[i]->name, *col, options, &entry);
      if (ignored_mesh) continue;
      spheres.insert(spheres.end(), cover.begin(), cover.end());
      model.cover_report.push_back(entry);
    }
    AddLinkSpheres(static_cast<int>(i), std::move(spheres), options.remove_contained_spheres, &model);
  }
  Finalize(options, path, &model);
  return model;
}

// ---------------------------------------------------------------------------
// YAML (modified DH). The file's keys are declared once below
// (core/params.h); the model is built from what they read.
namespace {

// A fixed frame: modified DH parameters of its joint from the parent link.
struct DhFrameEntry {
  std::optional<std::string> name;
  std::string link;
  std::optional<std::string> parent;
  double a = 0.0;
  double d = 0.0;
  double alpha = 0.0;
  double theta = 0.0;

  template <class Archive>
  void VisitFrame(Archive* ar) {
    ar->Visit(IPLAN_NVP(name, "joint name (default: LINK_fixed)"));
    ar->Visit(IPLAN_NVP_REQUIRED(link, "child link name, new"));
    ar->Visit(IPLAN_NVP(parent, "parent link (default: the previous one)"));
    ar->Visit(IPLAN_NVP_REQUIRED(a, "m; modified DH a"));
    ar->Visit(IPLAN_NVP_REQUIRED(d, "m; modified DH d"));
    ar->Visit(IPLAN_NVP_REQUIRED(alpha, "rad; modified DH alpha"));
    ar->Visit(IPLAN_NVP(theta, "rad; modified DH theta offset"));
  }
  template <class Archive>
  void Serialize(Archive* ar) {
    VisitFrame(ar);
  }
};

// A movable joint: a frame with a type and limits.
struct DhJointEntry : DhFrameEntry {
  std::string type = "revolute";
  double lower = 0.0;
  double upper = 0.0;
  double velocity = 0.0;
  std::optional<double> acceleration;
  std::optional<double> jerk;

  template <class Archive>
  void Serialize(Archive* ar) {
    VisitFrame(ar);
    ar->Visit(IPLAN_NVP(type, "revolute or prismatic"));
    ar->Visit(IPLAN_NVP_REQUIRED(lower, "rad or m; lower position limit"));
    ar->Visit(IPLAN_NVP_REQUIRED(upper, "rad or m; upper position limit"));
    ar->Visit(IPLAN_NVP_REQUIRED(velocity, "rad/s or m/s; > 0"));
    ar->Visit(IPLAN_NVP(acceleration, "rad/s^2 or m/s^2 (default: RobotModelOptions)"));
    ar->Visit(IPLAN_NVP(jerk, "rad/s^3 or m/s^3 (default: RobotModelOptions)"));
  }
};

struct SphereEntry {
  std::string link;
  std::array<double, 3> centre = {0.0, 0.0, 0.0};
  double radius = 0.0;
  template <class Archive>
  void Serialize(Archive* ar) {
    ar->Visit(IPLAN_NVP_REQUIRED(link, "link the sphere moves with"));
    ar->Visit(IPLAN_NVP_REQUIRED(centre, "m; in the link frame"));
    ar->Visit(IPLAN_NVP_REQUIRED(radius, "m; > 0"));
  }
};

struct CapsuleEntry {
  std::string link;
  std::array<double, 3> p1 = {0.0, 0.0, 0.0};
  std::array<double, 3> p2 = {0.0, 0.0, 0.0};
  double radius = 0.0;
  template <class Archive>
  void Serialize(Archive* ar) {
    ar->Visit(IPLAN_NVP_REQUIRED(link, "link the capsule moves with"));
    ar->Visit(IPLAN_NVP_REQUIRED(p1, "m; first end of the axis, link frame"));
    ar->Visit(IPLAN_NVP_REQUIRED(p2, "m; second end of the axis, link frame"));
    ar->Visit(IPLAN_NVP_REQUIRED(radius, "m; > 0"));
  }
};

struct BoxEntry {
  std::string link;
  std::array<double, 3> centre = {0.0, 0.0, 0.0};
  std::array<double, 3> half_extents = {0.0, 0.0, 0.0};
  template <class Archive>
  void Serialize(Archive* ar) {
    ar->Visit(IPLAN_NVP_REQUIRED(link, "link the box moves with"));
    ar->Visit(IPLAN_NVP_REQUIRED(centre, "m; box centre, link frame (axes along the link's)"));
    ar->Visit(IPLAN_NVP_REQUIRED(half_extents, "m; > 0"));
  }
};

struct RobotFile {
  std::string name;
  std::string convention;
  std::string base_link;
  std::vector<DhJointEntry> joints;
  std::vector<DhFrameEntry> fixed_frames;
  std::vector<SphereEntry> spheres;
  std::vector<CapsuleEntry> capsules;
  std::vector<BoxEntry> boxes;
  std::string tool_link;

  template <class Archive>
  void Serialize(Archive* ar) {
    ar->Visit(IPLAN_NVP_REQUIRED(name, "robot name"));
    ar->Visit(IPLAN_NVP(tool_link, "link whose pose pose goals give (default: none said; the planner takes the last link)"));
    ar->Visit(IPLAN_NVP_REQUIRED(convention, "modified_dh (the only one)"));
    ar->Visit(IPLAN_NVP_REQUIRED(base_link, "name of the base link"));
    ar->Visit(IPLAN_NVP_REQUIRED(joints, "movable joints, base to tip"));
    ar->Visit(IPLAN_NVP(fixed_frames, "fixed frames (flange, tool)"));
    ar->Visit(IPLAN_NVP(spheres, "collision spheres"));
    ar->Visit(IPLAN_NVP(capsules, "collision capsules, covered by spheres"));
    ar->Visit(IPLAN_NVP(boxes, "collision boxes, covered by spheres"));
  }
  std::string Validate() const {
    if (convention != "modified_dh") return "convention '" + convention + "' is not supported (only 'modified_dh')";
    if (joints.empty()) return "'joints' must be a non-empty list";
    return "";
  }
};

Eigen::Vector3d ToVector(const std::array<double, 3>& v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

// Modified DH: RotX(alpha) TransX(a) RotZ(theta) TransZ(d).
Eigen::Isometry3d ModifiedDh(double a, double d, double alpha, double theta) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.rotate(Eigen::AngleAxisd(alpha, Eigen::Vector3d::UnitX()));
  X.translate(Eigen::Vector3d(a, 0, 0));
  X.rotate(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
  X.translate(Eigen::Vector3d(0, 0, d));
  return X;
}

// Appends the joint of `n` and its child link; `limits` is set for movable joints.
void AddFrame(const DhFrameEntry& n, const DhJointEntry* movable, const std::string& where,
              const RobotModelOptions& options, const std::string& path, RobotModel* model) {
  Joint j;
  if (model->FindLink(n.link) >= 0) Fail(path, "link '" + n.link + "' defined twice");
  j.name = n.name ? *n.name : n.link + "_fixed";
  if (n.parent) {
    j.parent_link = model->FindLink(*n.parent);
    if (j.parent_link < 0) Fail(path, "parent '" + *n.parent + "' of " + where + " is unknown");
  } else {
    j.parent_link = static_cast<int>(model->link_names.size()) - 1;
  }
  j.X_PJ = ModifiedDh(n.a, n.d, n.alpha, n.theta);
  j.axis = Eigen::Vector3d::UnitZ();
  if (movable) {
    if (movable->type == "revolute") {
      j.type = JointType::kRevolute;
    } else if (movable->type == "prismatic") {
      j.type = JointType::kPrismatic;  // DH prismatic joints translate along z after the offset d.
    } else {
      Fail(path, "type '" + movable->type + "' of " + where + " must be revolute or prismatic");
    }
    j.limits.lower = movable->lower;
    j.limits.upper = movable->upper;
    j.limits.velocity = movable->velocity;
    j.limits.acceleration = movable->acceleration.value_or(options.default_acceleration);
    j.limits.jerk = movable->jerk.value_or(options.default_jerk);
    if (!(j.limits.lower < j.limits.upper) || !(j.limits.velocity > 0) || !(j.limits.acceleration > 0) ||
        !(j.limits.jerk > 0)) {
      std::ostringstream msg;
      msg << where << ": invalid limits lower=" << j.limits.lower << " upper=" << j.limits.upper
          << " velocity=" << j.limits.velocity << " acceleration=" << j.limits.acceleration
          << " jerk=" << j.limits.jerk;
      Fail(path, msg.str());
    }
  }
  j.child_link = static_cast<int>(model->link_names.size());
  model->link_names.push_back(n.link);
  model->link_parent_joint.push_back(static_cast<int>(model->joints.size()));
  model->joints.push_back(j);
}

// The spheres of the file's spheres, capsules and boxes, per link.
std::vector<std::vector<Sphere>> CoverLinks(const RobotFile& f, const RobotModelOptions& options,
                                            const std::string& path, RobotModel* model) {
  std::vector<std::vector<Sphere>> per_link(model->link_names.size());
  auto link_of = [&](const std::string& link, const std::string& where) {
    const int l = model->FindLink(link);
    if (l < 0) Fail(path, "link '" + link + "' of " + where + " is unknown");
    return l;
  };
  auto add = [&](int link, std::vector<Sphere> cover, const CoverReport& report) {
    per_link[link].insert(per_link[link].end(), cover.begin(), cover.end());
    model->cover_report.push_back({model->link_names[link], report, {}, std::nullopt});
  };
  for (std::size_t i = 0; i < f.spheres.size(); ++i) {
    const SphereEntry& s = f.spheres[i];
    const std::string where = "spheres[" + std::to_string(i) + "]";
    const int l = link_of(s.link, where);
    if (!(s.radius > 0)) Fail(path, where + ": radius " + std::to_string(s.radius) + " must be positive");
    CoverReport rep;
    rep.shape = "sphere";
    rep.num_spheres = 1;
    rep.shape_volume = 4.0 / 3.0 * kPi * s.radius * s.radius * s.radius;
    add(l, {{ToVector(s.centre), s.radius}}, rep);
  }
  for (std::size_t i = 0; i < f.capsules.size(); ++i) {
    const CapsuleEntry& c = f.capsules[i];
    const std::string where = "capsules[" + std::to_string(i) + "]";
    const int l = link_of(c.link, where);
    CoverReport rep;
    try {
      add(l, CoverCapsule(ToVector(c.p1), ToVector(c.p2), c.radius, options.cover, &rep), rep);
    } catch (const std::invalid_argument& e) {
      Fail(path, where + ": " + e.what());
    }
  }
  for (std::size_t i = 0; i < f.boxes.size(); ++i) {
    const BoxEntry& b = f.boxes[i];
    const std::string where = "boxes[" + std::to_string(i) + "]";
    const int l = link_of(b.link, where);
    CoverReport rep;
    Eigen::Isometry3d X_LB = Eigen::Isometry3d::Identity();
    X_LB.translation() = ToVector(b.centre);
    try {
      add(l, CoverBox(ToVector(b.half_extents), X_LB, options.cover, &rep), rep);
    } catch (const std::invalid_argument& e) {
      Fail(path, where + ": " + e.what());
    }
  }
  return per_link;
}

}  // namespace

RobotModel LoadRobotModelFromYaml(const std::string& path, const RobotModelOptions& options) {
  if (const std::string why = options.cover.Validate(); !why.empty()) Fail(path, why);
  const RobotFile f = core::LoadParamsFile<RobotFile>(path, {}, core::ConfigSection::EmptyFile::kError);
  RobotModel model;
  model.name = f.name;
  model.link_names.push_back(f.base_link);
  model.link_parent_joint.push_back(-1);
  for (std::size_t i = 0; i < f.joints.size(); ++i) {
    AddFrame(f.joints[i], &f.joints[i], "joints[" + std::to_string(i) + "]", options, path, &model);
  }
  for (std::size_t i = 0; i < f.fixed_frames.size(); ++i) {
    AddFrame(f.fixed_frames[i], nullptr, "fixed_frames[" + std::to_string(i) + "]", options, path, &model);
  }
  std::vector<std::vector<Sphere>> per_link = CoverLinks(f, options, path, &model);
  for (std::size_t l = 0; l < per_link.size(); ++l) {
    AddLinkSpheres(static_cast<int>(l), std::move(per_link[l]), options.remove_contained_spheres, &model);
  }
  if (!f.tool_link.empty() && model.FindLink(f.tool_link) < 0) Fail(path, "key 'tool_link': no link '" + f.tool_link + "'");
  model.tool_link = f.tool_link;
  Finalize(options, path, &model);
  return model;
}

}  // namespace iplan::collision

#include "iplan/collision/scene.h"

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "iplan/core/params.h"

#include "check.h"

namespace iplan::collision {

std::string SceneParams::Validate() const {
  std::ostringstream msg;
  for (size_t i = 0; i < objects.size(); ++i) {
    const SceneObject& o = objects[i];
    const std::string where = "object " + std::to_string(i) + " ('" + o.name + "')";
    if (!o.X_WO.matrix().allFinite()) return where + ": pose is not finite";
    if (o.shape == SceneObject::Shape::kBox) {
      if (!(o.size.minCoeff() > 0.0) || !o.size.allFinite()) {
        msg << where << ": box size [" << o.size.transpose() << "] must be positive";
        return msg.str();
      }
    } else {
      if (!(o.radius > 0.0) || !(o.length > 0.0) || !std::isfinite(o.radius) ||
          !std::isfinite(o.length)) {
        msg << where << ": cylinder radius = " << o.radius << ", length = " << o.length
            << " must be positive";
        return msg.str();
      }
    }
  }
  return {};
}

namespace {

// One entry of a scene file as written (the pose as xyz + rpy, the shape by
// name); ToObject makes the SceneObject.
struct SceneObjectEntry {
  std::string name;
  std::string type;
  std::array<double, 3> xyz = {0.0, 0.0, 0.0};
  std::array<double, 3> rpy = {0.0, 0.0, 0.0};
  std::optional<std::array<double, 3>> size;
  std::optional<double> radius;
  std::optional<double> length;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP_REQUIRED(name, "object name (allowed_collisions refer to it)"));
    a->Visit(IPLAN_NVP_REQUIRED(type, "box or cylinder"));
    a->Visit(IPLAN_NVP_REQUIRED(xyz, "m; position of the object frame in the world"));
    a->Visit(IPLAN_NVP(rpy, "rad; orientation, URDF convention R = Rz(y) Ry(p) Rx(r)"));
    a->Visit(IPLAN_NVP(size, "m; box: full edge lengths"));
    a->Visit(IPLAN_NVP(radius, "m; cylinder radius"));
    a->Visit(IPLAN_NVP(length, "m; cylinder length along the local z"));
  }

  // The keys a shape takes; "" when they fit.
  std::string CheckShape(const std::string& where) const {
    if (type == "box") {
      if (radius || length) return where + ": a box takes 'size', not radius/length";
      if (!size) return "missing key 'size' in " + where;
    } else if (type == "cylinder") {
      if (size) return where + ": a cylinder takes 'radius' and 'length', not 'size'";
      if (!radius || !length) return where + ": a cylinder needs 'radius' and 'length'";
    } else {
      return where + ": type '" + type + "' must be 'box' or 'cylinder'";
    }
    return "";
  }

  SceneObject ToObject() const {
    SceneObject o;
    o.name = name;
    o.X_WO.setIdentity();
    o.X_WO.translation() = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    o.X_WO.linear() = (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
                       Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
                       Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
                          .toRotationMatrix();
    if (type == "box") {
      o.shape = SceneObject::Shape::kBox;
      o.size = Eigen::Vector3d((*size)[0], (*size)[1], (*size)[2]);
    } else {
      o.shape = SceneObject::Shape::kCylinder;
      o.radius = *radius;
      o.length = *length;
    }
    return o;
  }
};

// A scene file: `objects:`, a list of entries.
struct SceneFile {
  std::vector<SceneObjectEntry> objects;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP_REQUIRED(objects, "the static objects"));
  }
  std::string Validate() const {
    for (std::size_t i = 0; i < objects.size(); ++i) {
      if (std::string why = objects[i].CheckShape("objects[" + std::to_string(i) + "]"); !why.empty()) return why;
    }
    return ToParams().Validate();
  }
  SceneParams ToParams() const {
    SceneParams p;
    for (const SceneObjectEntry& e : objects) p.objects.push_back(e.ToObject());
    return p;
  }
};

}  // namespace

SceneParams LoadSceneParams(const std::string& path) {
  return core::LoadParamsFile<SceneFile>(path, {}, core::ConfigSection::EmptyFile::kError).ToParams();
}

}  // namespace iplan::collision

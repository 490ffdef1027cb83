#include "iplan/collision/scene.h"

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
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

struct StaticScene::Impl {
  SceneParams params;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
};

StaticScene::StaticScene(SceneParams params) : impl_(std::make_unique<Impl>()) {
  if (const std::string why = params.Validate(); !why.empty()) {
    throw std::invalid_argument("SceneParams: " + why);
  }
  impl_->params = std::move(params);
  for (const SceneObject& o : impl_->params.objects) {
    std::shared_ptr<fcl::CollisionGeometryd> geometry;
    if (o.shape == SceneObject::Shape::kBox) {
      geometry = std::make_shared<fcl::Boxd>(o.size);
    } else {
      geometry = std::make_shared<fcl::Cylinderd>(o.radius, o.length);
    }
    impl_->objects.push_back(std::make_unique<fcl::CollisionObjectd>(
        geometry, fcl::Transform3d(o.X_WO.matrix())));
  }
}

StaticScene::~StaticScene() = default;
StaticScene::StaticScene(StaticScene&&) noexcept = default;
StaticScene& StaticScene::operator=(StaticScene&&) noexcept = default;

const SceneParams& StaticScene::params() const { return impl_->params; }
int StaticScene::num_objects() const { return static_cast<int>(impl_->objects.size()); }

double StaticScene::CalcSignedDistance(int object, const Eigen::Vector3d& p_WS,
                                       double radius) const {
  IPLAN_COLLISION_DEMAND(object >= 0 && object < num_objects());
  // FCL's sphere primitives need a positive radius; a point is a sphere of
  // radius 0, handled by shifting the distance.
  const double r = std::max(radius, 1e-6);
  fcl::Transform3d X_WS = fcl::Transform3d::Identity();
  X_WS.translation() = p_WS;
  fcl::CollisionObjectd sphere(std::make_shared<fcl::Sphered>(r), X_WS);
  fcl::DistanceRequestd request;
  request.enable_signed_distance = true;
  request.enable_nearest_points = false;
  request.distance_tolerance = 1e-10;  // GJK stops at 1e-6 m by default
  // FCL 0.7 with libccd asserts in EPA for some sphere/cylinder penetrations;
  // the independent solver does not, and matches closed forms to 1e-10 m
  // (scene_test).
  request.gjk_solver_type = fcl::GST_INDEP;
  fcl::DistanceResultd result;
  fcl::distance(&sphere, impl_->objects[object].get(), request, result);
  return result.min_distance + (r - radius);
}

SceneDistance StaticScene::CalcMinimumDistance(const Eigen::Matrix3Xd& p_WS,
                                               const std::vector<double>& radii) const {
  IPLAN_COLLISION_DEMAND(static_cast<size_t>(p_WS.cols()) == radii.size());
  SceneDistance best;
  best.distance = std::numeric_limits<double>::infinity();
  for (Eigen::Index s = 0; s < p_WS.cols(); ++s) {
    for (int o = 0; o < num_objects(); ++o) {
      const double d = CalcSignedDistance(o, p_WS.col(s), radii[static_cast<size_t>(s)]);
      if (d < best.distance) {
        best.distance = d;
        best.sphere = static_cast<int>(s);
        best.object = o;
      }
    }
  }
  return best;
}

bool StaticScene::CheckCollision(const Eigen::Matrix3Xd& p_WS, const std::vector<double>& radii,
                                 double margin) const {
  return CalcMinimumDistance(p_WS, radii).distance < margin;
}

}  // namespace iplan::collision

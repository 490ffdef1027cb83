#include "iplan/collision/scene.h"

#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <yaml-cpp/yaml.h>

#include "iplan/core/yaml.h"

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

SceneParams LoadSceneParams(const std::string& path) {
  auto fail = [&](const std::string& what) { throw std::runtime_error(path + ": " + what); };
  SceneParams p;
  try {
    const YAML::Node root = core::LoadYamlFile(path);  // a key twice is an error
    if (!root.IsMap()) fail("top level must be a map");
    for (const auto& kv : root) {
      if (kv.first.as<std::string>() != "objects") {
        fail("unknown key '" + kv.first.as<std::string>() + "' at the top level");
      }
    }
    const YAML::Node objects = root["objects"];
    if (!objects || !objects.IsSequence()) fail("'objects' must be a list");
    for (size_t i = 0; i < objects.size(); ++i) {
      const YAML::Node n = objects[i];
      const std::string where = "objects[" + std::to_string(i) + "]";
      if (!n.IsMap()) fail(where + " must be a map");
      static const std::set<std::string> kAllowed = {"name", "type", "xyz", "rpy",
                                                     "size", "radius", "length"};
      for (const auto& kv : n) {
        const std::string key = kv.first.as<std::string>();
        if (kAllowed.count(key) == 0) fail("unknown key '" + key + "' in " + where);
      }
      auto vec3 = [&](const char* key, bool required) -> Eigen::Vector3d {
        if (!n[key]) {
          if (required) fail("missing key '" + std::string(key) + "' in " + where);
          return Eigen::Vector3d::Zero();
        }
        const auto v = n[key].as<std::vector<double>>();
        if (v.size() != 3) fail("'" + std::string(key) + "' in " + where + " must have 3 numbers");
        return Eigen::Vector3d(v[0], v[1], v[2]);
      };
      SceneObject o;
      if (!n["name"]) fail("missing key 'name' in " + where);
      o.name = n["name"].as<std::string>();
      if (!n["type"]) fail("missing key 'type' in " + where);
      const std::string type = n["type"].as<std::string>();
      const Eigen::Vector3d xyz = vec3("xyz", true);
      const Eigen::Vector3d rpy = vec3("rpy", false);
      o.X_WO.setIdentity();
      o.X_WO.translation() = xyz;
      o.X_WO.linear() = (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
                            .toRotationMatrix();
      if (type == "box") {
        o.shape = SceneObject::Shape::kBox;
        if (n["radius"] || n["length"]) fail(where + ": a box takes 'size', not radius/length");
        o.size = vec3("size", true);
      } else if (type == "cylinder") {
        o.shape = SceneObject::Shape::kCylinder;
        if (n["size"]) fail(where + ": a cylinder takes 'radius' and 'length', not 'size'");
        if (!n["radius"] || !n["length"]) fail(where + ": a cylinder needs 'radius' and 'length'");
        o.radius = n["radius"].as<double>();
        o.length = n["length"].as<double>();
      } else {
        fail(where + ": type '" + type + "' must be 'box' or 'cylinder'");
      }
      p.objects.push_back(o);
    }
  } catch (const YAML::Exception& e) {
    fail(std::string("invalid YAML: ") + e.what());
  }
  if (const std::string why = p.Validate(); !why.empty()) fail(why);
  return p;
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

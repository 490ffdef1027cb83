#include "iplan/collision/static_scene.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include "check.h"

namespace iplan::collision {

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

#include "iplan/collision/static_scene.h"

#include <cmath>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

namespace iplan::collision {
namespace {

// Analytic signed distance from a point to a box / cylinder in its frame.
double PointBox(const Eigen::Vector3d& p, const Eigen::Vector3d& h) {
  const Eigen::Vector3d q = p.cwiseAbs() - h;
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(q.maxCoeff(), 0.0);
  return outside + inside;
}

double PointCylinder(const Eigen::Vector3d& p, double r, double half_length) {
  const double radial = p.head<2>().norm() - r;
  const double axial = std::abs(p.z()) - half_length;
  const double outside = std::hypot(std::max(radial, 0.0), std::max(axial, 0.0));
  return outside + std::min(std::max(radial, axial), 0.0);
}

Eigen::Isometry3d RandomPose(std::mt19937_64* rng) {
  std::normal_distribution<double> n01;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(n01(*rng), n01(*rng), n01(*rng), n01(*rng))
                   .normalized().toRotationMatrix();
  X.translation() = Eigen::Vector3d(n01(*rng), n01(*rng), n01(*rng));
  return X;
}

TEST(SceneTest, SignedDistancesMatchClosedForm) {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> n01;
  SceneParams params;
  for (int i = 0; i < 10; ++i) {
    SceneObject o;
    o.name = "o" + std::to_string(i);
    o.X_WO = RandomPose(&rng);
    if (i % 2 == 0) {
      o.shape = SceneObject::Shape::kBox;
      o.size = Eigen::Vector3d(0.1 + u01(rng), 0.1 + u01(rng), 0.1 + u01(rng));
    } else {
      o.shape = SceneObject::Shape::kCylinder;
      o.radius = 0.05 + 0.3 * u01(rng);
      o.length = 0.1 + u01(rng);
    }
    params.objects.push_back(o);
  }
  const StaticScene scene(params);
  int inside = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int k = trial % 10;
    const SceneObject& o = params.objects[k];
    const Eigen::Vector3d p_O = 0.6 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    const double radius = trial % 7 == 0 ? 0.0 : 0.1 * u01(rng);
    const double expected =
        (o.shape == SceneObject::Shape::kBox ? PointBox(p_O, 0.5 * o.size)
                                             : PointCylinder(p_O, o.radius, 0.5 * o.length)) -
        radius;
    if (expected < 0) ++inside;
    const double got = scene.CalcSignedDistance(k, o.X_WO * p_O, radius);
    EXPECT_NEAR(got, expected, 1e-10) << "object " << k << " trial " << trial;
  }
  EXPECT_GT(inside, 100);  // penetrations are exercised too
}

TEST(SceneTest, MinimumDistanceAndCollision) {
  SceneParams params;
  SceneObject table;
  table.name = "table";
  table.X_WO.translation() = Eigen::Vector3d(0, 0, -0.5);
  table.size = Eigen::Vector3d(2, 2, 1);  // top face at z = 0
  params.objects.push_back(table);
  const StaticScene scene(params);
  Eigen::Matrix3Xd c(3, 3);
  c << 0, 0.5, 0.1, 0, 0, 0, 0.3, 0.2, 0.05;
  const std::vector<double> r = {0.1, 0.1, 0.1};
  const SceneDistance d = scene.CalcMinimumDistance(c, r);
  EXPECT_EQ(d.sphere, 2);
  EXPECT_EQ(d.object, 0);
  EXPECT_NEAR(d.distance, -0.05, 1e-6);
  EXPECT_TRUE(scene.CheckCollision(c, r));
  c(2, 2) = 0.13;
  EXPECT_FALSE(scene.CheckCollision(c, r));
  EXPECT_TRUE(scene.CheckCollision(c, r, 0.05));  // within the margin
}

TEST(SceneTest, LoadsShippedConfigAndRejectsBadFiles) {
  const SceneParams p = LoadSceneParams(std::string(IPLAN_SOURCE_DIR) + "/config/scenes/cell.yaml");
  ASSERT_EQ(p.objects.size(), 4u);
  EXPECT_EQ(p.objects[2].shape, SceneObject::Shape::kCylinder);
  EXPECT_NEAR(p.objects[3].X_WO.linear()(1, 0), std::sin(0.3), 1e-15);
  const std::string bad = ::testing::TempDir() + "scene_bad.yaml";
  std::ofstream(bad) << "objects:\n  - {name: t, type: box, xyz: [0, 0, 0], size: [1, 1, -1]}\n";
  try {
    LoadSceneParams(bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("object 0 ('t'): box size [ 1  1 -1] must be positive"),
              std::string::npos) << e.what();
  }
  std::ofstream(bad) << "objects:\n  - {name: t, type: sphere, xyz: [0, 0, 0]}\n";
  try {
    LoadSceneParams(bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("type 'sphere' must be 'box' or 'cylinder'"),
              std::string::npos) << e.what();
  }
  std::ofstream(bad) << "objects:\n  - {name: t, type: box, xyz: [0, 0, 0], sise: [1, 1, 1]}\n";
  try {
    LoadSceneParams(bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), bad + ": missing key 'size' in objects[0]\n" + bad +
                                         ": unknown key 'objects[0].sise'");
  }
  std::ofstream(bad) << "objects:\n  - {name: c, type: cylinder, xyz: [0, 0, 0], radius: 0.1, length: 1, size: [1, 1, 1]}\n";
  try {
    LoadSceneParams(bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), bad + ": objects[0]: a cylinder takes 'radius' and 'length', not 'size'");
  }
  std::ofstream(bad) << "objects:\n  - {name: c, type: box, size: [1, 1, 1]}\n";
  try {
    LoadSceneParams(bad);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), bad + ": key 'objects[0].xyz': is required but missing");
  }
}

TEST(SceneTest, AKeyWrittenTwiceIsAnError) {
  // yaml-cpp would keep the first position and ignore the moved one.
  const std::string bad = ::testing::TempDir() + "scene_twice.yaml";
  std::ofstream(bad) << "objects:\n  - {name: t, type: box, xyz: [0, 0, 0], size: [1, 1, 1], xyz: [1, 0, 0]}\n";
  try {
    LoadSceneParams(bad);
    ADD_FAILURE() << "a key written twice was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), bad + ": key 'objects[0].xyz': appears twice (lines 2 and 2)");
  }
}

}  // namespace
}  // namespace iplan::collision

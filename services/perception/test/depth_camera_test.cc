// The simulated depth camera: geometry without noise (sphere depth, table
// height, occlusion, image bounds), and the noise model's spread (seeded).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "services/perception/core/depth_camera.h"

namespace iplan::perception {
namespace {

// A camera 1.2 m above the world origin's table, 1.0 m back, looking at the origin.
DepthCameraParams Params(bool noise) {
  DepthCameraParams p;
  p.X_WS = cloud::CameraPoseLookAt({0.0, -1.0, 1.2}, {0.0, 0.0, 0.0});
  p.add_noise = noise;
  return p;
}

DepthScene::Box Table() {
  DepthScene::Box b;
  b.X_WO.translation() = Eigen::Vector3d(0, 0, -0.025);
  b.size = Eigen::Vector3d(1.2, 0.9, 0.05);
  return b;
}

int Finite(const cloud::Cloud& c) {
  int n = 0;
  for (const auto& p : c.points) n += p.allFinite();
  return n;
}

TEST(DepthCameraTest, SphereDepthAndImageArea) {
  const DepthCameraParams params = Params(false);
  SimulatedDepthCamera cam(params);
  DepthScene scene;
  const Eigen::Vector3d centre_W(0.0, 0.0, 0.3);
  scene.spheres.push_back({centre_W, 0.1});
  cloud::Cloud c;
  cam.Render(scene, &c);
  ASSERT_EQ(c.width, 640);
  ASSERT_EQ(c.height, 480);
  const Eigen::Vector3d centre_S = params.X_WS.inverse() * centre_W;
  // Every returned point lies on the sphere.
  double nearest = 1e9;
  for (const auto& p : c.points) {
    if (!p.allFinite()) continue;
    EXPECT_NEAR((p.cast<double>() - centre_S).norm(), 0.1, 1e-4);
    nearest = std::min(nearest, static_cast<double>(p.norm()));
  }
  EXPECT_NEAR(nearest, centre_S.norm() - 0.1, 2e-3);
  // The disc it covers: pi (f r / sqrt(d^2 - r^2))^2 pixels for a sphere on the axis-ish.
  const double d = centre_S.norm();
  const double area = M_PI * std::pow(525.0 * 0.1 / std::sqrt(d * d - 0.01), 2);
  EXPECT_NEAR(Finite(c), area, 0.06 * area);
}

TEST(DepthCameraTest, TableTopAtItsHeightAndOcclusion) {
  const DepthCameraParams params = Params(false);
  SimulatedDepthCamera cam(params);
  DepthScene scene;
  scene.boxes.push_back(Table());
  cloud::Cloud table_only;
  cam.Render(scene, &table_only);
  int on_top = 0, n = 0;
  for (const auto& p : table_only.points) {
    if (!p.allFinite()) continue;
    ++n;
    const Eigen::Vector3d p_W = params.X_WS * p.cast<double>();
    if (std::abs(p_W.z()) < 1e-4) ++on_top;
  }
  EXPECT_GT(n, 50000);
  EXPECT_GT(on_top, 0.95 * n);  // the rest: the front face of the 5 cm slab
  // A sphere on the table hides the table behind it.
  scene.spheres.push_back({Eigen::Vector3d(0, 0, 0.1), 0.1});
  cloud::Cloud both;
  cam.Render(scene, &both);
  const Eigen::Vector3d c_S = params.X_WS.inverse() * Eigen::Vector3d(0, 0, 0.1);
  const int u = static_cast<int>(std::lround(525.0 * c_S.x() / c_S.z() + 319.5));
  const int v = static_cast<int>(std::lround(525.0 * c_S.y() / c_S.z() + 239.5));
  const std::size_t i = static_cast<std::size_t>(v) * 640 + u;
  EXPECT_NEAR((both.points[i].cast<double>() - c_S).norm(), 0.1, 1e-3);
  EXPECT_LT(both.points[i].z(), table_only.points[i].z() - 0.05);
}

TEST(DepthCameraTest, AxialNoiseMatchesTheModel) {
  // A wall 1.5 m ahead, square to the view: depth spread = sigma_z(1.5).
  DepthCameraParams params;
  params.X_WS = cloud::CameraPoseLookAt({0, 0, 1}, {1, 0, 1});
  params.seed = 7;
  SimulatedDepthCamera cam(params);
  DepthScene scene;
  DepthScene::Box wall;
  wall.X_WO.translation() = Eigen::Vector3d(1.5 + 0.05, 0, 1);
  wall.size = Eigen::Vector3d(0.1, 4, 4);
  scene.boxes.push_back(wall);
  cloud::Cloud c;
  cam.Render(scene, &c);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (const auto& p : c.points) {
    if (!p.allFinite()) continue;
    sum += p.z() - 1.5;
    sum2 += (p.z() - 1.5) * (p.z() - 1.5);
    ++n;
  }
  ASSERT_EQ(n, 640 * 480);
  const double sigma = std::sqrt(sum2 / n - (sum / n) * (sum / n));
  const double expected = 0.0012 + 0.0019 * (1.5 - 0.4) * (1.5 - 0.4);  // Nguyen et al. 2012
  EXPECT_NEAR(sigma, expected, 0.03 * expected);
  EXPECT_NEAR(sum / n, 0.0, 1e-4);
}

TEST(DepthCameraTest, RangeLimitsAndNothingBehind) {
  DepthCameraParams params = Params(false);
  params.max_range = 1.0;  // the table is farther: nothing
  SimulatedDepthCamera cam(params);
  DepthScene scene;
  scene.boxes.push_back(Table());
  scene.spheres.push_back({Eigen::Vector3d(0, -3, 2), 0.3});  // behind the camera
  cloud::Cloud c;
  cam.Render(scene, &c);
  EXPECT_EQ(Finite(c), 0);
}

}  // namespace
}  // namespace iplan::perception

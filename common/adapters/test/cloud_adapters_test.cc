// PointCloud2 <-> Cloud: our layout round-trips; a ROS 2 driver's layout
// (x y z padded to 16 bytes, rgb after, rows padded) decodes; NaN pixels
// stay NaN at their place.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "iplan/adapters/cloud_adapters.h"
#include "iplan/core/params.h"

namespace iplan::services {
namespace {

TEST(CloudAdaptersTest, RoundTripKeepsEveryPointAndNaN) {
  cloud::Cloud c;
  c.width = 4;
  c.height = 3;
  for (int i = 0; i < 12; ++i) c.points.emplace_back(0.1f * i, -0.2f * i, 1.0f + 0.01f * i);
  c.points[5].setConstant(std::nanf(""));
  msg::PointCloud2 m;
  ToPointCloud2(c, msg::Time{}, "depth_camera", &m);
  EXPECT_EQ(m.point_step, 12u);
  EXPECT_EQ(m.row_step, 48u);
  EXPECT_FALSE(m.is_dense);
  cloud::Cloud back;
  ASSERT_EQ(FromPointCloud2(m, &back), std::nullopt);
  ASSERT_EQ(back.width, 4);
  ASSERT_EQ(back.height, 3);
  for (int i = 0; i < 12; ++i) {
    if (i == 5) {
      EXPECT_FALSE(back.points[5].allFinite());
    } else {
      EXPECT_EQ(back.points[static_cast<std::size_t>(i)], c.points[static_cast<std::size_t>(i)]) << i;
    }
  }
}

TEST(CloudAdaptersTest, RosDriverLayoutWithPaddingDecodes) {
  // As depth_image_proc publishes: x y z at 0 4 8, rgb at 16, point_step 32,
  // plus 8 bytes of row padding; fields in another order.
  msg::PointCloud2 m;
  m.height = 2;
  m.width = 3;
  m.fields = {{"rgb", 16, msg::PointField::FLOAT32, 1}, {"z", 8, msg::PointField::FLOAT32, 1},
              {"x", 0, msg::PointField::FLOAT32, 1}, {"y", 4, msg::PointField::FLOAT32, 1}};
  m.point_step = 32;
  m.row_step = 3 * 32 + 8;
  m.data.assign(static_cast<std::size_t>(m.row_step) * 2, 0xAB);
  for (int r = 0; r < 2; ++r) {
    for (int col = 0; col < 3; ++col) {
      const float p[3] = {static_cast<float>(col), static_cast<float>(r), 2.0f};
      std::memcpy(m.data.data() + r * m.row_step + col * 32, p, 12);
    }
  }
  cloud::Cloud c;
  ASSERT_EQ(FromPointCloud2(m, &c), std::nullopt);
  ASSERT_EQ(c.size(), 6u);
  EXPECT_EQ(c.points[4], Eigen::Vector3f(1, 1, 2));
  EXPECT_EQ(c.points[2], Eigen::Vector3f(2, 0, 2));
}

TEST(CloudAdaptersTest, CameraPoseFromConfig) {
  auto file = core::ConfigSection::FromString("camera: {position: [0, -1, 1], look_at: [0, 0, 1]}\n", "test.yaml");
  cloud::CameraLookAt camera;
  core::ReadParams(file.Section("camera"), &camera);
  const Eigen::Isometry3d X_WS = camera.Pose();
  EXPECT_TRUE(file.Problems().empty());
  // Looking along +y of the world: z_S = +y_W, x_S = +x_W... right is +x, down is -z.
  EXPECT_TRUE(X_WS.linear().col(2).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(X_WS.linear().col(0).isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(X_WS.linear().col(1).isApprox(-Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(X_WS.translation().isApprox(Eigen::Vector3d(0, -1, 1)));
}

}  // namespace
}  // namespace iplan::services

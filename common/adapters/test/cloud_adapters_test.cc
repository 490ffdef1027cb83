// PointCloud2 <-> Cloud: our layout round-trips; a ROS 2 driver's layout
// (x y z padded to 16 bytes, rgb after, rows padded) decodes; NaN pixels
// stay NaN at their place. Depth images: a cloud on its pixels' rays comes
// back within half a millimetre; malformed images are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

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

// A 4x3 camera and a cloud whose points lie on their pixels' rays.
cloud::CameraIntrinsics SmallCamera() {
  cloud::CameraIntrinsics k;
  k.width = 4, k.height = 3, k.fx = 5.0, k.fy = 6.0, k.cx = 1.5, k.cy = 1.0;
  return k;
}
cloud::Cloud OnRays(const cloud::CameraIntrinsics& k) {
  cloud::Cloud c;
  c.width = k.width, c.height = k.height;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const double z = 0.8004 + 0.1234567 * (u + k.width * v);
      c.points.emplace_back((u - k.cx) * z / k.fx, (v - k.cy) * z / k.fy, z);
    }
  }
  return c;
}

TEST(CloudAdaptersTest, DepthImageRoundTripIsWithinHalfAMillimetre) {
  const cloud::CameraIntrinsics k = SmallCamera();
  cloud::Cloud c = OnRays(k);
  c.points[6].setConstant(std::nanf(""));
  msg::Image m;
  ToDepthImage(c, msg::Time{}, "depth_camera", &m);
  EXPECT_EQ(m.encoding, "16UC1");
  EXPECT_EQ(m.step, 8u);
  ASSERT_EQ(m.data.size(), 24u);  // a quarter of the cloud's 12 bytes per point
  cloud::Cloud back;
  ASSERT_EQ(FromDepthImage(m, k, &back), std::nullopt);
  ASSERT_EQ(back.width, 4);
  ASSERT_EQ(back.height, 3);
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    if (i == 6) {
      EXPECT_FALSE(back.points[i].allFinite());
      continue;
    }
    // z to the millimetre; x and y scale with it along the ray.
    EXPECT_LE((back.points[i] - c.points[i]).norm(), 0.0005 * 1.2) << i;
    EXPECT_NE(back.points[i], c.points[i]) << i;  // no depth here is a whole millimetre
  }
}

TEST(CloudAdaptersTest, FloatDepthImageDecodesAndZeroOrNaNIsNoReturn) {
  const cloud::CameraIntrinsics k = SmallCamera();
  msg::Image m;
  m.width = 4, m.height = 3, m.encoding = "32FC1", m.step = 16;
  m.data.resize(48);
  float depth[12];
  for (int i = 0; i < 12; ++i) depth[i] = 1.0f + 0.5f * i;
  depth[2] = 0.0f;
  depth[9] = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(m.data.data(), depth, 48);
  cloud::Cloud c;
  ASSERT_EQ(FromDepthImage(m, k, &c), std::nullopt);
  EXPECT_FALSE(c.points[2].allFinite());
  EXPECT_FALSE(c.points[9].allFinite());
  // Pixel (u, v) = (3, 1), index 7, depth 4.5 m.
  EXPECT_FLOAT_EQ(c.points[7].x(), static_cast<float>((3 - 1.5) * 4.5 / 5.0));
  EXPECT_FLOAT_EQ(c.points[7].y(), 0.0f);
  EXPECT_FLOAT_EQ(c.points[7].z(), 4.5f);
  depth[4] = -1.0f;
  std::memcpy(m.data.data(), depth, 48);
  EXPECT_EQ(FromDepthImage(m, k, &c), std::string("pixel 4 has depth -1.000000"));
}

TEST(CloudAdaptersTest, MalformedDepthImagesAreRefused) {
  const cloud::CameraIntrinsics k = SmallCamera();
  msg::Image good;
  ToDepthImage(OnRays(k), msg::Time{}, "depth_camera", &good);
  cloud::Cloud c;
  msg::Image m = good;
  m.encoding = "rgb8";
  EXPECT_EQ(FromDepthImage(m, k, &c),
            std::string("depth image encoding 'rgb8' is not supported (16UC1 in mm or 32FC1 in m)"));
  m = good;
  m.is_bigendian = 1;
  EXPECT_EQ(FromDepthImage(m, k, &c), std::string("big-endian depth images are not supported"));
  m = good;
  cloud::CameraIntrinsics vga;
  EXPECT_EQ(FromDepthImage(m, vga, &c), std::string("depth image is 4x3, the camera's intrinsics 640x480"));
  m = good;
  m.step = 6;
  m.data.resize(18);
  EXPECT_EQ(FromDepthImage(m, k, &c),
            std::string("depth image step 6 does not fit width 4 x 2 bytes or data 18 bytes"));
}

// A calibration round trip; binning and a region of interest as ROS's
// image_geometry applies them: a 2x2-binned 320x240 window of the VGA
// camera, 100 pixels right and 40 down, is 160x120 with fx / 2 and
// (cx - 100) / 2.
TEST(CloudAdaptersTest, CameraInfoGivesTheImagesIntrinsics) {
  const cloud::CameraIntrinsics vga;  // 640x480, 525, 319.5, 239.5
  msg::CameraInfo m;
  ToCameraInfo(vga, msg::Time{12, 5}, "depth_camera", &m);
  EXPECT_EQ(m.header.frame_id, "depth_camera");
  EXPECT_EQ(m.header.stamp.sec, 12);
  // width, height, fx, fy, cx, cy
  const auto text = [](const cloud::CameraIntrinsics& c) {
    return core::ParamText(std::vector<double>{1.0 * c.width, 1.0 * c.height, c.fx, c.fy, c.cx, c.cy});
  };
  cloud::CameraIntrinsics k;
  k.fx = 1;  // overwritten
  ASSERT_EQ(FromCameraInfo(m, &k), std::nullopt);
  EXPECT_EQ(text(k), "[640.0, 480.0, 525.0, 525.0, 319.5, 239.5]");
  m.binning_x = 2, m.binning_y = 2;
  m.roi.x_offset = 100, m.roi.y_offset = 40, m.roi.width = 320, m.roi.height = 240;
  ASSERT_EQ(FromCameraInfo(m, &k), std::nullopt);
  EXPECT_EQ(text(k), "[160.0, 120.0, 262.5, 262.5, 109.75, 99.75]");  // (319.5 - 100) / 2, (239.5 - 40) / 2
}

TEST(CloudAdaptersTest, UnusableCalibrationsAreRefused) {
  msg::CameraInfo good;
  ToCameraInfo(cloud::CameraIntrinsics{}, msg::Time{}, "depth_camera", &good);
  const cloud::CameraIntrinsics before;
  const auto refused = [&](msg::CameraInfo m) {
    cloud::CameraIntrinsics k = before;
    const std::optional<std::string> why = FromCameraInfo(m, &k);
    EXPECT_EQ(k.fx, before.fx) << "left as it was";
    return why.value_or("(accepted)");
  };
  msg::CameraInfo m = good;
  m.k.fill(0);
  EXPECT_EQ(refused(m), "the camera is not calibrated (k is all zero)");
  m = good, m.k[4] = -525;
  EXPECT_EQ(refused(m), "focal lengths fx 525.0, fy -525.0 are not positive");
  m = good, m.k[1] = 0.5;
  EXPECT_EQ(refused(m), "k is not a pinhole without skew (fx 0 cx; 0 fy cy; 0 0 1)");
  m = good, m.d[0] = 0.1;
  EXPECT_EQ(refused(m), "distortion 'plumb_bob' has non-zero coefficients: the depth images must be rectified");
  m = good, m.roi.x_offset = 400, m.roi.width = 320, m.roi.height = 240;
  EXPECT_EQ(refused(m), "region of interest 320x240 at (400, 0) is outside the 640x480 image");
  m = good, m.width = 0;
  EXPECT_EQ(refused(m), "image size 0x480 is not 1..4096 pixels a side");
  m = good, m.binning_x = 1000;
  EXPECT_EQ(refused(m), "image size 0x480 is not 1..4096 pixels a side");
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

// Unit tests of iplan::cloud on synthetic depth images (ray-cast boxes on a
// table, seeded Kinect-like noise), hand-written PCD files and YAML files.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <map>

#include <Eigen/Geometry>

#include "iplan/cloud/cloud.h"
#include "iplan/cloud/evaluate.h"
#include "iplan/cloud/noise.h"
#include "iplan/cloud/oriented_box.h"
#include "iplan/cloud/pipeline.h"

namespace iplan::cloud {
namespace {

struct Box {
  Eigen::Vector3f lo, hi;  // world frame, metres
};

// A 640x480 camera 0.9 m above a table (world z = 0), pitched down by 50
// degrees, looking along world +y. truth: 0 miss, 1 table, 20 + k box k.
struct Scene {
  Cloud cloud;
  std::vector<std::uint32_t> truth;
  Eigen::Matrix3f R_WS;
  Eigen::Vector3f p_WS{0.0f, -0.6f, 0.9f};
};

Scene Render(const std::vector<Box>& boxes, std::uint32_t seed, double noise_scale = 1.0) {
  Scene s;
  const float pitch = 50.0f * static_cast<float>(M_PI) / 180.0f;
  // S: x right, y down, z forward. Level camera looking along W +y: x_S = x_W,
  // y_S = -z_W, z_S = y_W; then pitched down about x_S.
  Eigen::Matrix3f level;
  level << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  s.R_WS = level * Eigen::AngleAxisf(-pitch, Eigen::Vector3f::UnitX()).toRotationMatrix();
  s.cloud.width = 640;
  s.cloud.height = 480;
  s.cloud.points.assign(640 * 480, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  s.truth.assign(640 * 480, 0);
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss(0.0f, 1.0f);
  const DepthNoiseParams noise;
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) {
      const Eigen::Vector3f d_S((u - 319.5f) / 525.0f, (v - 239.5f) / 525.0f, 1.0f);
      const Eigen::Vector3f d_W = s.R_WS * d_S;
      float best = std::numeric_limits<float>::infinity();
      std::uint32_t id = 0;
      if (d_W.z() < 0) {
        const float t = -s.p_WS.z() / d_W.z();
        const Eigen::Vector3f p = s.p_WS + t * d_W;
        if (std::abs(p.x()) < 0.8f && p.y() > -0.3f && p.y() < 1.5f) best = t, id = 1;
      }
      for (std::size_t k = 0; k < boxes.size(); ++k) {  // slab test
        float t0 = 0, t1 = best;
        for (int a = 0; a < 3; ++a) {
          const float inv = 1.0f / d_W[a];
          float ta = (boxes[k].lo[a] - s.p_WS[a]) * inv, tb = (boxes[k].hi[a] - s.p_WS[a]) * inv;
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
        }
        if (t0 < t1 && t0 < best) best = t0, id = 20 + static_cast<std::uint32_t>(k);
      }
      if (id == 0) continue;
      Eigen::Vector3f p_S = best * d_S;  // d_S has z = 1, so best is the depth
      p_S *= 1.0f + static_cast<float>(noise_scale * AxialSigma(noise, p_S.z())) * gauss(rng) / p_S.z();
      s.cloud.points[v * 640 + u] = p_S;
      s.truth[v * 640 + u] = id;
    }
  return s;
}

// Two boxes standing apart on the table, in W (metres).
std::vector<Box> TwoBoxes() {
  return {{{-0.25f, 0.45f, 0.0f}, {-0.05f, 0.60f, 0.12f}}, {{0.10f, 0.40f, 0.0f}, {0.25f, 0.55f, 0.20f}}};
}

TEST(ObstaclePipeline, FindsTheTableAndTwoBoxes) {
  const Scene s = Render(TwoBoxes(), 1);
  ObstaclePipeline pipeline(CloudParams{});
  const Result r = pipeline.Process(s.cloud);
  ASSERT_EQ(r.labels.size(), s.cloud.size());
  const SceneScore score = ScoreScene(s.truth, r.labels);
  EXPECT_EQ(score.objects, 2);
  EXPECT_EQ(score.found, 2);
  EXPECT_EQ(score.false_obstacles, 0);
  EXPECT_GE(static_cast<double>(score.table_labelled) / score.table_points, 0.98);
  // The table plane: world z = 0, its normal (world up) seen in S.
  ASSERT_TRUE(r.table.found);
  const Eigen::Vector3f up_S = s.R_WS.transpose() * Eigen::Vector3f::UnitZ();
  EXPECT_GT(r.table.normal.dot(up_S), std::cos(1.0 * M_PI / 180.0));
  EXPECT_NEAR(r.table.offset, 0.9f, 0.005f);  // the camera's height over the table
  EXPECT_EQ(r.table.points, std::count(r.labels.begin(), r.labels.end(), kLabelTable));
  // Obstacles: ids 1..n, labels and indices agree, boxes hold their points.
  ASSERT_EQ(r.obstacles.size(), 2u);
  for (std::size_t k = 0; k < r.obstacles.size(); ++k) {
    const Obstacle& o = r.obstacles[k];
    EXPECT_EQ(o.id, static_cast<int>(k) + 1);
    for (const int i : o.indices) {
      EXPECT_EQ(r.labels[i], LabelOfObstacle(o.id));
      const Eigen::Vector3f p_B = o.orientation.conjugate() * (s.cloud.points[i] - o.centre);
      EXPECT_TRUE((p_B.cwiseAbs().array() <= o.half_extents.array() + 1e-5f).all()) << p_B.transpose();
    }
  }
  EXPECT_GE(r.obstacles[0].indices.size(), r.obstacles[1].indices.size());
}

TEST(ObstaclePipeline, SelfFilterRemovesThePointsInsideTheRobotSpheres) {
  const Scene s = Render(TwoBoxes(), 2);
  // A sphere around the first box (W centre -> S).
  Sphere sphere;
  sphere.centre = s.R_WS.transpose() * (Eigen::Vector3f(-0.15f, 0.525f, 0.06f) - s.p_WS);
  sphere.radius = 0.16f;
  ObstaclePipeline pipeline(CloudParams{});
  const Result r = pipeline.Process(s.cloud, {sphere});
  const SceneScore score = ScoreScene(s.truth, r.labels);
  EXPECT_EQ(score.found, 1);
  EXPECT_EQ(score.false_obstacles, 0);
  ASSERT_EQ(r.obstacles.size(), 1u);
  const float r2 = std::pow(sphere.radius + CloudParams{}.self_filter_margin, 2.0f);
  for (std::size_t i = 0; i < s.cloud.size(); ++i)
    if (s.cloud.points[i].allFinite() && (s.cloud.points[i] - sphere.centre).squaredNorm() <= r2) {
      EXPECT_EQ(r.labels[i], kLabelRemoved) << i;
    }
}

TEST(ObstaclePipeline, CropBoxRemovesWhatLiesOutside) {
  const Scene s = Render(TwoBoxes(), 3);
  CloudParams p;
  p.crop_max.x() = 0.0f;  // the left half of the image only (box 1 is left)
  ObstaclePipeline pipeline(p);
  const Result r = pipeline.Process(s.cloud);
  ASSERT_EQ(r.obstacles.size(), 1u);
  for (const int i : r.obstacles[0].indices) EXPECT_EQ(s.truth[i], 20u);
  for (std::size_t i = 0; i < s.cloud.size(); ++i)
    if (s.cloud.points[i].allFinite() && s.cloud.points[i].x() > 0.0f) {
      EXPECT_EQ(r.labels[i], kLabelRemoved);
    }
}

TEST(ObstaclePipeline, SplitsABoxStandingOnAnother) {
  // A small box on a large flat one: one connected surface in depth, told
  // apart by the concave crease where they meet (no colour in this cloud).
  const std::vector<Box> stack = {{{-0.20f, 0.40f, 0.0f}, {0.20f, 0.70f, 0.05f}},
                                  {{-0.08f, 0.50f, 0.05f}, {0.06f, 0.62f, 0.17f}}};
  const Scene s = Render(stack, 4);
  ObstaclePipeline pipeline(CloudParams{});
  const SceneScore ours = ScoreScene(s.truth, pipeline.Process(s.cloud).labels);
  EXPECT_EQ(ours.objects, 2);
  EXPECT_EQ(ours.found, 2);
  EXPECT_EQ(ours.false_obstacles, 0);
  // Without the crease cues (concavity, steps) they are one obstacle,
  // which finds neither.
  CloudParams no_concavity;
  no_concavity.concave_margin = 2.0f;
  no_concavity.step_angle_deg = 90.0f;
  ObstaclePipeline plain(no_concavity);
  EXPECT_EQ(ScoreScene(s.truth, plain.Process(s.cloud).labels).found, 0);
}

TEST(ObstaclePipeline, BadCloudsGiveEmptyResultsOrAClearError) {
  ObstaclePipeline pipeline(CloudParams{});
  Cloud nan;
  nan.width = 640;
  nan.height = 480;
  nan.points.assign(640 * 480, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  Result r = pipeline.Process(nan);
  EXPECT_FALSE(r.table.found);
  EXPECT_TRUE(r.obstacles.empty());
  EXPECT_EQ(std::count(r.labels.begin(), r.labels.end(), kLabelRemoved), 640 * 480);
  r = pipeline.Process(Cloud{});
  EXPECT_TRUE(r.labels.empty());
  EXPECT_TRUE(r.obstacles.empty());
  Cloud wrong = nan;
  wrong.points.pop_back();
  try {
    pipeline.Process(wrong);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("width * height (640 * 480) != 307199 points"), std::string::npos)
        << e.what();
  }
  // Unorganised (one row) and tiny clouds: no image neighbours beyond the
  // row, no normals; processed without crashing.
  Cloud row;
  row.width = 2000;
  row.height = 1;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  for (int i = 0; i < row.width; ++i) row.points.emplace_back(u(rng), 0.4f, 1.0f + u(rng));
  r = pipeline.Process(row);
  EXPECT_EQ(r.labels.size(), row.size());
  Cloud one;
  one.width = one.height = 1;
  one.points = {{0.0f, 0.0f, 1.0f}};
  r = pipeline.Process(one);
  EXPECT_EQ(r.labels, std::vector<int>{kLabelRemoved});
  Cloud small = Render(TwoBoxes(), 6).cloud;
  small.width = 4;
  small.height = 3;
  small.points.resize(12);
  EXPECT_EQ(pipeline.Process(small).labels.size(), 12u);
  CloudParams bad;
  bad.stride = 0;
  EXPECT_THROW(ObstaclePipeline{bad}, std::invalid_argument);
}

// Points on the faces of a box (size, yaw about z, centre; W, z up) a
// camera up and to the front-left sees: the top and two sides, 5 mm apart,
// with 0.5 mm of seeded noise.
std::vector<Eigen::Vector3f> VisibleFaces(const Eigen::Vector3f& size, float yaw, const Eigen::Vector3f& centre) {
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.0005f);
  const Eigen::Matrix3f R = Eigen::AngleAxisf(yaw, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  const Eigen::Vector3f h = 0.5f * size;
  std::vector<Eigen::Vector3f> out;
  auto face = [&](int axis, float sign) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (float u = -h[a]; u <= h[a]; u += 0.005f)
      for (float v = -h[b]; v <= h[b]; v += 0.005f) {
        Eigen::Vector3f p_B;
        p_B[axis] = sign * h[axis];
        p_B[a] = u;
        p_B[b] = v;
        out.push_back(centre + R * p_B + Eigen::Vector3f(noise(rng), noise(rng), noise(rng)));
      }
  };
  face(2, 1.0f);   // top
  face(0, -1.0f);  // the side facing -x_B
  face(1, -1.0f);  // the side facing -y_B
  return out;
}

TEST(FitOrientedBox, UprightBoxOfARotatedBoxIsTight) {
  const Eigen::Vector3f size(0.30f, 0.12f, 0.10f), centre(0.2f, 0.1f, 0.05f);
  const float yaw = 0.5f;
  const std::vector<Eigen::Vector3f> points = VisibleFaces(size, yaw, centre);
  std::vector<int> all(points.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  const OrientedBox box = FitOrientedBox(points, all, &up);
  // The true box, to the noise (its extremes reach about 2 mm beyond each
  // face): edges within 5 mm, yaw within 1 degree (x along the long side,
  // modulo 180 degrees), z up, centre within 3 mm.
  EXPECT_LT((2.0f * box.half_extents - size).cwiseAbs().maxCoeff(), 0.005f) << box.half_extents.transpose();
  const Eigen::Matrix3f R = box.orientation.toRotationMatrix();
  EXPECT_GT(R.col(2).dot(up), 0.9999f);
  const Eigen::Vector3f long_side(std::cos(yaw), std::sin(yaw), 0.0f);
  EXPECT_GT(std::abs(R.col(0).dot(long_side)), std::cos(1.0f * static_cast<float>(M_PI) / 180.0f));
  EXPECT_GE(R.col(0).x(), 0.0f);  // x_B . x_F >= 0
  EXPECT_LT((box.centre - centre).norm(), 0.003f);
  EXPECT_NEAR(R.determinant(), 1.0f, 1e-5f);
  for (const Eigen::Vector3f& p : points)
    EXPECT_TRUE(((R.transpose() * (p - box.centre)).cwiseAbs().array() <= box.half_extents.array() + 1e-5f).all());
  // The axis-aligned box around the same points is 1.7 times the volume.
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
  for (const Eigen::Vector3f& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const float oriented = 8.0f * box.half_extents.prod(), aligned = (hi - lo).prod(), truth = size.prod();
  EXPECT_LT(oriented, 1.1f * truth);
  EXPECT_GT(aligned, 1.6f * truth);
  // Without an up direction: the principal axes, still holding every point.
  const OrientedBox pca = FitOrientedBox(points, all, nullptr);
  const Eigen::Matrix3f Rp = pca.orientation.toRotationMatrix();
  EXPECT_NEAR(Rp.determinant(), 1.0f, 1e-5f);
  for (const Eigen::Vector3f& p : points)
    EXPECT_TRUE(((Rp.transpose() * (p - pca.centre)).cwiseAbs().array() <= pca.half_extents.array() + 1e-5f).all());
  // No points: a zero box.
  EXPECT_EQ(FitOrientedBox(points, {}, &up).half_extents, Eigen::Vector3f::Zero());
}

TEST(TextbookPipeline, FindsTheTwoSeparateBoxes) {
  const Scene s = Render(TwoBoxes(), 5);
  const Result r = TextbookPipeline(s.cloud, CloudParams{});
  const SceneScore score = ScoreScene(s.truth, r.labels);
  EXPECT_EQ(score.found, 2);
  EXPECT_EQ(score.false_obstacles, 0);
  EXPECT_GE(static_cast<double>(score.table_labelled) / score.table_points, 0.98);
}

TEST(ScoreScene, CountsFoundFalseAndTable) {
  // Table: points 0-3; object 20: points 4-9 (6); object 30: points 10-11
  // (2, below min_object_points = 3, so no object); point 12 invalid.
  const std::vector<std::uint32_t> truth = {1, 1, 2, 1, 20, 20, 20, 20, 20, 20, 30, 30, 0};
  ScoreParams p;
  p.min_object_points = 3;
  // Obstacle 1 (label 2) = 4 of 20's 6 points, pure: found. Obstacle 2
  // (label 3) = 2 of 20 and 30's 2: finds nothing, so it is false.
  SceneScore s = ScoreScene(truth, {1, 1, 1, 0, 2, 2, 2, 2, 3, 3, 3, 3, 0}, p);
  EXPECT_EQ(s.objects, 1);
  EXPECT_EQ(s.found, 1);
  EXPECT_EQ(s.obstacles, 2);
  EXPECT_EQ(s.false_obstacles, 1);
  EXPECT_EQ(s.table_points, 4);
  EXPECT_EQ(s.table_labelled, 3);
  // Obstacle 1 plus the invalid point: purity 4/5 = 0.8, still found.
  s = ScoreScene(truth, {1, 1, 1, 0, 2, 2, 2, 2, 3, 3, 3, 3, 2}, p);
  EXPECT_EQ(s.found, 1);
  // Plus a table point too: purity 4/6 < 0.8, not found; both obstacles false.
  s = ScoreScene(truth, {1, 1, 1, 2, 2, 2, 2, 2, 3, 3, 3, 3, 2}, p);
  EXPECT_EQ(s.found, 0);
  EXPECT_EQ(s.false_obstacles, 2);
  EXPECT_EQ(s.table_labelled, 3);
  // Share: 2 of 6 points is below one half.
  s = ScoreScene(truth, {1, 1, 1, 1, 2, 2, 3, 3, 4, 4, 0, 0, 0}, p);
  EXPECT_EQ(s.found, 0);
  EXPECT_EQ(s.false_obstacles, 3);
  const SceneScore sum = Add(s, s);
  EXPECT_EQ(sum.false_obstacles, 6);
  EXPECT_EQ(sum.table_points, 8);
  EXPECT_THROW(ScoreScene(truth, std::vector<int>(3, 0)), std::invalid_argument);
}

TEST(Noise, NguyenModelAndPointCovariances) {
  const DepthNoiseParams noise;
  EXPECT_NEAR(AxialSigma(noise, 1.0), 0.0012 + 0.0019 * 0.36, 1e-12);
  EXPECT_NEAR(AxialSigma(noise, 0.4), 0.0012, 1e-12);
  const Eigen::Matrix3d c = PointCovariance(noise, Eigen::Vector3f(0.1f, -0.2f, 2.0f));
  const double lateral = 0.8 * 2.0 / 525.0;
  EXPECT_NEAR(c(0, 0), lateral * lateral, 1e-12);
  EXPECT_NEAR(c(1, 1), lateral * lateral, 1e-12);
  EXPECT_NEAR(c(2, 2), std::pow(0.0012 + 0.0019 * 1.6 * 1.6, 2), 1e-12);
  EXPECT_EQ(c(0, 1), 0.0);
  Cloud cloud;
  cloud.width = 3;
  cloud.height = 1;
  cloud.points = {{0, 0, 1}, Eigen::Vector3f::Constant(NAN), {0, 0, 2}};
  const NoisyPoints n = PointsWithNoise(cloud, {0, 1, 2}, noise);
  ASSERT_EQ(n.points.size(), 2u);
  EXPECT_GT(n.covariances[1](2, 2), n.covariances[0](2, 2));
  EXPECT_THROW(PointsWithNoise(cloud, {3}, noise), std::out_of_range);
  DepthNoiseParams bad;
  bad.focal_px = 0;
  EXPECT_EQ(bad.Validate(), "focal_px must be > 0");
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + std::to_string(getpid()) + "_" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(LoadPcd, ReadsFieldsAndRejectsBadFiles) {
  const std::string path = WriteTemp("ok.pcd",
                                     "VERSION 0.7\nFIELDS x y z rgba label\nSIZE 4 4 4 4 4\nTYPE F F F U U\n"
                                     "COUNT 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n"
                                     "DATA ascii\n0.1 0.2 0.3 4278190335 1\nnan nan nan 0 0\n");
  const Cloud c = LoadPcd(path);
  EXPECT_EQ(c.width, 2);
  EXPECT_EQ(c.height, 1);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_FLOAT_EQ(c.points[0].z(), 0.3f);
  EXPECT_FALSE(c.points[1].allFinite());
  ASSERT_EQ(c.rgba.size(), 2u);
  EXPECT_EQ(c.rgba[0], 4278190335u);
  ASSERT_EQ(c.label.size(), 2u);
  EXPECT_EQ(c.label[0], 1u);
  const std::string no_xyz = WriteTemp("noxyz.pcd",
                                       "VERSION 0.7\nFIELDS a\nSIZE 4\nTYPE F\nCOUNT 1\nWIDTH 1\nHEIGHT 1\n"
                                       "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1\n");
  try {
    LoadPcd(no_xyz);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), no_xyz + ": PCD file has no x y z fields");
  }
  EXPECT_THROW(LoadPcd(WriteTemp("garbage.pcd", "not a pcd\n")), std::runtime_error);
  const std::string doubles = WriteTemp("doubles.pcd",
                                        "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\n"
                                        "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2 3\n");
  try {
    LoadPcd(doubles);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), doubles + ": field 'x' must be one float32 (F 4 1)");
  }
  const std::string header =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 100\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 100\n";
  const std::string truncated = WriteTemp("truncated.pcd", header + "DATA binary\nabcdefgh");
  try {
    LoadPcd(truncated);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), truncated + ": cannot read PCD file");
  }
  EXPECT_THROW(LoadPcd(WriteTemp("truncated2.pcd", header + "DATA binary_compressed\nabcdefgh")),
               std::runtime_error);
  EXPECT_THROW(LoadPcd("/nonexistent/x.pcd"), std::runtime_error);
}

void ExpectLoadError(const std::string& yaml, const std::string& message) {
  const std::string path = WriteTemp("params.yaml", yaml);
  try {
    LoadCloudParams(path);
    FAIL() << "no exception for " << yaml;
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path + ": " + message);
  }
}

TEST(LoadCloudParams, StrictKeysTypesAndValues) {
  const CloudParams p =
      LoadCloudParams(WriteTemp("good.yaml", "stride: 3\ncrop_min: [-1, -1, 0.5]\nconcave_margin: 0.3\n"));
  EXPECT_EQ(p.stride, 3);
  EXPECT_FLOAT_EQ(p.crop_min.z(), 0.5f);
  EXPECT_FLOAT_EQ(p.concave_margin, 0.3f);
  EXPECT_FLOAT_EQ(p.voxel_size, CloudParams{}.voxel_size);  // left out: default
  EXPECT_EQ(LoadCloudParams(WriteTemp("empty.yaml", "")).stride, CloudParams{}.stride);
  ExpectLoadError("strid: 2\n", "unknown key 'strid'");
  ExpectLoadError("stride: two\n", "key 'stride' has a value of the wrong type: 'two'");
  ExpectLoadError("crop_max: [1, 2]\n", "key 'crop_max' needs 3 numbers [x, y, z], got 2");
  ExpectLoadError("stride: 0\n", "stride must be in 1..8, got 0");
  ExpectLoadError("crop_min: [0, 0, 3]\n", "crop_min must be below crop_max on every axis, got axis 2: 3.0 .. 2.5");
  ExpectLoadError("- 1\n", "cloud params must be a map");
  const std::string twice = WriteTemp("twice.yaml", "stride: 2\nstride: 3\n");
  try {
    LoadCloudParams(twice);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'stride': appears twice"), std::string::npos) << e.what();
  }
}

TEST(CloudParams, DefaultsAreValidAndConfigFileWritesThemOut) {
  EXPECT_EQ(CloudParams{}.Validate(), "");
  // config/cloud_pipeline.yaml documents the defaults: every key, every value.
  const CloudParams file = LoadCloudParams(std::string(IPLAN_SOURCE_DIR) + "/config/cloud_pipeline.yaml");
  const CloudParams d;
  EXPECT_EQ(file.crop_min, d.crop_min);
  EXPECT_EQ(file.crop_max, d.crop_max);
  EXPECT_FLOAT_EQ(file.self_filter_margin, d.self_filter_margin);
  EXPECT_EQ(file.plane_sample_stride, d.plane_sample_stride);
  EXPECT_EQ(file.plane_max_iterations, d.plane_max_iterations);
  EXPECT_FLOAT_EQ(file.plane_fit_distance, d.plane_fit_distance);
  EXPECT_FLOAT_EQ(file.table_distance, d.table_distance);
  EXPECT_FLOAT_EQ(file.table_distance_per_m2, d.table_distance_per_m2);
  EXPECT_EQ(file.min_table_points, d.min_table_points);
  EXPECT_FLOAT_EQ(file.max_object_height, d.max_object_height);
  EXPECT_EQ(file.stride, d.stride);
  EXPECT_FLOAT_EQ(file.cluster_distance, d.cluster_distance);
  EXPECT_FLOAT_EQ(file.cluster_distance_per_m2, d.cluster_distance_per_m2);
  EXPECT_EQ(file.min_obstacle_points, d.min_obstacle_points);
  EXPECT_EQ(file.normal_window_px, d.normal_window_px);
  EXPECT_FLOAT_EQ(file.concave_margin, d.concave_margin);
  EXPECT_EQ(file.crease_offset_px, d.crease_offset_px);
  EXPECT_FLOAT_EQ(file.step_normal_deg, d.step_normal_deg);
  EXPECT_FLOAT_EQ(file.step_angle_deg, d.step_angle_deg);
  EXPECT_EQ(file.min_part_points, d.min_part_points);
  EXPECT_FLOAT_EQ(file.concave_region_share, d.concave_region_share);
  EXPECT_FLOAT_EQ(file.voxel_size, d.voxel_size);
  EXPECT_FLOAT_EQ(file.euclidean_tolerance, d.euclidean_tolerance);
  EXPECT_EQ(file.textbook_min_cluster, d.textbook_min_cluster);
}

}  // namespace
}  // namespace iplan::cloud

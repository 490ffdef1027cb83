// The cloud service's stage on frames of the simulated depth camera: a box
// on the table becomes one static obstacle (stable id, centre and size
// right), a moving person-sized body becomes human points near its truth,
// the robot's own spheres are filtered from the joint state (over its path
// around the stamp), the table is removed. And the tracker on its own: settle, move, lose.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include "services/cloud/core/cloud_stage.h"
#include "services/perception/core/depth_camera.h"
#include "iplan/cloud/camera.h"
#include "iplan/collision/robot_model.h"

namespace iplan::cloud_service {
namespace {

using perception::DepthScene;
using perception::SimulatedDepthCamera;

constexpr int64_t kFrameNs = 33'333'333;

const Eigen::Isometry3d kCamera = cloud::CameraPoseLookAt({0.45, 1.3, 1.1}, {0.6, 0.0, 0.1});

CloudStageParams Params() {
  CloudStageParams p;
  p.X_WS = kCamera;
  p.workspace_min = Eigen::Vector3d(-0.3, -0.6, -0.1);
  p.workspace_max = Eigen::Vector3d(1.8, 0.8, 1.4);
  return p;
}

DepthScene::Box Box(const Eigen::Vector3d& centre, const Eigen::Vector3d& size, double yaw = 0) {
  DepthScene::Box b;
  b.X_WO = Eigen::Translation3d(centre) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  b.size = size;
  return b;
}

DepthScene Table() {
  DepthScene s;
  s.boxes.push_back(Box({0.45, 0.0, -0.025}, {1.2, 0.9, 0.05}));
  return s;
}

SimulatedDepthCamera Camera() {
  perception::DepthCameraParams p;
  p.X_WS = kCamera;
  p.seed = 3;
  return SimulatedDepthCamera(p);
}

TEST(CloudStageTest, BoxOnTheTableIsOneStaticObstacleWithStableId) {
  SimulatedDepthCamera cam = Camera();
  DepthScene scene = Table();
  const Eigen::Vector3d centre(0.6, 0.1, 0.1), size(0.2, 0.3, 0.2);
  scene.boxes.push_back(Box(centre, size));
  CloudStage stage(Params(), nullptr);
  cloud::Cloud c;
  uint32_t id = 0;
  for (int f = 0; f < 15; ++f) {
    cam.Render(scene, &c);
    const StageOutput out = stage.Process(&c, std::nullopt, 1000 + f * kFrameNs);
    EXPECT_TRUE(out.table_found);
    EXPECT_GT(out.table_points, 50000);
    if (f < 9) {  // static_frames = 10: pending, counted as human points meanwhile
      EXPECT_TRUE(out.obstacles.empty()) << "frame " << f;
      EXPECT_FALSE((out.human.size() == 0));
      continue;
    }
    ASSERT_EQ(out.obstacles.size(), 1u) << "frame " << f;
    EXPECT_TRUE((out.human.size() == 0)) << "frame " << f;
    const cell::ObstacleBox& o = out.obstacles[0];
    if (id == 0) id = o.id;
    EXPECT_EQ(o.id, id);
    EXPECT_EQ(o.first_seen_ns, 1000);
    // Centre within 2 cm, edges within 3 cm (the bottom 7 mm are table band),
    // the box's x along its longer side: extents along W's axes compared.
    EXPECT_LT((o.centre - centre).norm(), 0.02) << o.centre.transpose();
    const Eigen::Vector3d extent_W = o.orientation.toRotationMatrix().cwiseAbs() * (2 * o.half_extents);
    EXPECT_LT((extent_W - size).cwiseAbs().maxCoeff(), 0.03) << extent_W.transpose();
    EXPECT_GE(o.half_extents.x(), o.half_extents.y());
  }
}

// Issue 29: a box turned on the table is reported as large as it is, turned
// as it is (not the larger axis-aligned box around it).
TEST(CloudStageTest, ATurnedBoxIsReportedWithItsSizeAndTurn) {
  SimulatedDepthCamera cam = Camera();
  DepthScene scene = Table();
  const Eigen::Vector3d centre(0.6, 0.1, 0.1), size(0.3, 0.2, 0.2);
  const double yaw = 0.5;  // rad
  scene.boxes.push_back(Box(centre, size, yaw));
  CloudStage stage(Params(), nullptr);
  cloud::Cloud c;
  StageOutput out;
  for (int f = 0; f < 12; ++f) {
    cam.Render(scene, &c);
    out = stage.Process(&c, std::nullopt, f * kFrameNs);
  }
  ASSERT_EQ(out.obstacles.size(), 1u);
  const cell::ObstacleBox& o = out.obstacles[0];
  EXPECT_LT((o.centre - centre).norm(), 0.02) << o.centre.transpose();
  EXPECT_LT(((2 * o.half_extents) - size).cwiseAbs().maxCoeff(), 0.03) << o.half_extents.transpose();
  // Turned about W's z only, by the box's yaw (a box is the same turned by pi).
  const Eigen::Matrix3d R = o.orientation.toRotationMatrix();
  EXPECT_NEAR(R(2, 2), 1.0, 1e-9);
  const double error = std::remainder(std::atan2(R(1, 0), R(0, 0)) - yaw, M_PI);
  EXPECT_LT(std::abs(error), 0.05) << "yaw error " << error << " rad";
}

// The mean of upright boxes turns each one to within 45 degrees of the mean
// first: the same box seen at yaw 0.01 and at pi/2 - 0.01 (its x and y
// swapped) averages to yaw 0 with its own extents.
TEST(ClusterTrackerTest, TheMeanBoxTakesQuarterTurnsAsTheSameBox) {
  UprightBox mean;
  UprightBox a;
  a.centre = {0.5, 0.0, 0.1};
  a.yaw = 0.01;
  a.half_extents = {0.15, 0.1, 0.1};
  AddToMean(a, 0, &mean);
  UprightBox b = a;
  b.yaw = M_PI / 2 - 0.01;
  b.half_extents = {0.1, 0.15, 0.1};
  AddToMean(b, 1, &mean);
  EXPECT_NEAR(mean.yaw, 0.0, 1e-12);
  EXPECT_TRUE(mean.half_extents.isApprox(Eigen::Vector3d(0.15, 0.1, 0.1), 1e-12)) << mean.half_extents.transpose();
  UprightBox c = a;
  c.yaw = -M_PI + 0.03;  // the same box turned by pi
  c.centre.x() = 0.8;
  AddToMean(c, 2, &mean);
  EXPECT_NEAR(mean.yaw, 0.01, 1e-12);
  EXPECT_NEAR(mean.centre.x(), 0.6, 1e-12);
}

TEST(CloudStageTest, MovingPersonIsHumanPointsNearTheTruth) {
  SimulatedDepthCamera cam = Camera();
  CloudStage stage(Params(), nullptr);
  cloud::Cloud c;
  for (int f = 0; f < 20; ++f) {
    DepthScene scene = Table();
    // A torso-and-head column of spheres (0.6 m tall) drifting along y at 0.3 m/s.
    const double y = -0.2 + 0.01 * f;
    for (int k = 0; k < 4; ++k) scene.spheres.push_back({Eigen::Vector3d(1.1, y, 0.15 + 0.15 * k), 0.12});
    cam.Render(scene, &c);
    const StageOutput out = stage.Process(&c, std::nullopt, f * kFrameNs);
    EXPECT_TRUE(out.obstacles.empty()) << "frame " << f;
    ASSERT_GT(out.human.size(), 50) << "frame " << f;
    EXPECT_EQ(out.human.stamp_ns, f * kFrameNs);
    EXPECT_EQ(out.human.voxel_size, Params().human_voxel);
    EXPECT_EQ(out.human.Check(), std::nullopt);
    for (int i = 0; i < out.human.size(); ++i) {
      const Eigen::Vector3d mean = out.human.means.col(i);
      double surface = 1e9;
      for (const auto& s : scene.spheres) surface = std::min(surface, (mean - s.centre).norm() - s.radius);
      EXPECT_LT(std::abs(surface), 0.03);  // a 3 cm voxel's centroid near the surface
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(out.human.covariances[static_cast<std::size_t>(i)]);
      EXPECT_GT(eig.eigenvalues().minCoeff(), 0);
      EXPECT_LT(std::sqrt(eig.eigenvalues().maxCoeff()), 0.01);  // a few mm at 1.5 m
    }
  }
}

TEST(CloudStageTest, RobotSpheresAreFilteredGivenTheJointState) {
  // A one-link "robot": a sphere on a fixed base, from a minimal model.
  collision::RobotModel robot;
  robot.name = "ball";
  robot.link_names = {"base"};
  robot.link_parent_joint = {-1};
  robot.nq = 0;
  collision::CollisionSphere s;
  s.link = 0;
  s.p_LS = Eigen::Vector3d(0.4, -0.2, 0.3);
  s.radius = 0.12;
  robot.spheres.push_back(s);
  SimulatedDepthCamera cam = Camera();
  DepthScene scene = Table();
  scene.spheres.push_back({s.p_LS, s.radius});
  cloud::Cloud c;
  CloudStage filtered(Params(), &robot), unfiltered(Params(), &robot);
  cam.Render(scene, &c);
  cloud::Cloud copy = c;
  const StageOutput with_q = filtered.Process(&c, Eigen::VectorXd(0), 0);
  EXPECT_TRUE(with_q.self_filtered);
  EXPECT_EQ(with_q.clusters, 0);
  EXPECT_TRUE((with_q.human.size() == 0));
  const StageOutput without_q = unfiltered.Process(&copy, std::nullopt, 0);
  EXPECT_FALSE(without_q.self_filtered);
  EXPECT_EQ(without_q.clusters, 1);
  EXPECT_FALSE((without_q.human.size() == 0));  // the robot counts as human: cautious
}

// The camera saw the arm a little further along than the joint state at the
// cloud's stamp says (the two clocks' timing): the arm's edge is left as a
// human cluster; with the poses around the stamp (the service's
// self_filter_time) each sphere covers its path and nothing is left.
TEST(CloudStageTest, TheArmSeenAheadOfItsJointStateIsFilteredWithThePosesAroundTheStamp) {
  const collision::RobotModel robot =
      collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml");
  Eigen::VectorXd q(7), seen(7);
  q << 0.0, 0.2, 0.0, -1.8, 0.0, 2.0, 0.8;
  seen = q;
  seen[0] += 0.1;  // rad: the arm at 1 rad/s, 0.1 s apart
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, seen, &d);
  DepthScene scene = Table();
  for (std::size_t k = 0; k < robot.spheres.size(); ++k)
    scene.spheres.push_back({d.p_WS.col(static_cast<Eigen::Index>(k)), robot.spheres[k].radius});
  SimulatedDepthCamera cam = Camera();
  cloud::Cloud c;
  cam.Render(scene, &c);
  cloud::Cloud copy = c;
  CloudStage at_stamp(Params(), &robot), over_path(Params(), &robot);
  const StageOutput left = at_stamp.Process(&c, q, 0);
  EXPECT_TRUE(left.self_filtered);
  EXPECT_GT(left.human.size(), 20) << "the pose error leaves no sliver: the test shows nothing";
  Eigen::VectorXd before = q, after = q;
  before[0] -= 0.1;
  after[0] += 0.1;
  const StageOutput none = over_path.Process(&copy, q, 0, {before, after});
  EXPECT_TRUE(none.self_filtered);
  EXPECT_EQ(none.human.size(), 0);
  EXPECT_EQ(none.clusters, 0);
}

TEST(CloudStageTest, FramesWithoutJointStateLeaveTheTracksAlone) {
  // The robot's sphere beside a box on the table: 12 frames without the
  // joint state, then with it. The box must settle as a static obstacle
  // as if the unfiltered frames had not been (no merged track, no move).
  collision::RobotModel robot;
  robot.name = "ball";
  robot.link_names = {"base"};
  robot.link_parent_joint = {-1};
  collision::CollisionSphere s;
  s.link = 0;
  s.p_LS = Eigen::Vector3d(0.6, 0.1, 0.25);  // on top of the box
  s.radius = 0.06;
  robot.spheres.push_back(s);
  SimulatedDepthCamera cam = Camera();
  DepthScene scene = Table();
  const Eigen::Vector3d centre(0.6, 0.1, 0.1);
  scene.boxes.push_back(Box(centre, {0.2, 0.3, 0.2}));
  scene.spheres.push_back({s.p_LS, s.radius});
  CloudStage stage(Params(), &robot);
  cloud::Cloud c;
  for (int f = 0; f < 12; ++f) {
    cam.Render(scene, &c);
    const StageOutput out = stage.Process(&c, std::nullopt, f * kFrameNs);
    EXPECT_TRUE(out.obstacles.empty());
    EXPECT_FALSE((out.human.size() == 0));
  }
  StageOutput out;
  for (int f = 12; f < 22; ++f) {
    cam.Render(scene, &c);
    out = stage.Process(&c, Eigen::VectorXd(0), f * kFrameNs);
  }
  ASSERT_EQ(out.obstacles.size(), 1u);
  EXPECT_EQ(out.obstacles[0].first_seen_ns, 12 * kFrameNs);
  EXPECT_LT((out.obstacles[0].centre - centre).norm(), 0.02);
  EXPECT_TRUE((out.human.size() == 0));
}

TEST(CloudStageTest, WorkspaceCropRemovesWhatIsOutside) {
  SimulatedDepthCamera cam = Camera();
  DepthScene scene = Table();
  scene.boxes.push_back(Box({0.6, 0.1, 0.1}, {0.2, 0.2, 0.2}));
  CloudStageParams p = Params();
  p.workspace_max.x() = 0.4;  // the box is beyond
  CloudStage stage(p, nullptr);
  cloud::Cloud c;
  cam.Render(scene, &c);
  const StageOutput out = stage.Process(&c, std::nullopt, 0);
  EXPECT_GT(out.cropped_points, 10000);
  EXPECT_EQ(out.clusters, 0);
}

ClusterObservation Obs(const Eigen::Vector3d& c, double half = 0.05) {
  ClusterObservation o;
  o.centroid = c;
  o.box_min = c.array() - half;
  o.box_max = c.array() + half;
  o.points = 1000;
  return o;
}

TEST(ClusterTrackerTest, SettlesMovesAndIsLost) {
  TrackerParams p;
  p.static_frames = 3;
  p.lost_frames = 2;
  ClusterTracker t(p);
  // Frames 1-2 pending, frame 3 static.
  for (int f = 0; f < 3; ++f) {
    const auto idx = t.Update({Obs({0.5, 0, 0.1})}, f);
    ASSERT_EQ(t.tracks().size(), 1u);
    EXPECT_EQ(t.tracks()[0].cls, f < 2 ? TrackClass::kPending : TrackClass::kStatic) << f;
    EXPECT_EQ(idx[0], 0);
  }
  EXPECT_EQ(t.tracks()[0].id, 1u);
  EXPECT_EQ(t.tracks()[0].first_seen_ns, 0);
  // Seen only in part (its lower 2 cm: the arm hides the rest): the centroid
  // is 4 cm lower, but the visible box is within the settled one: still static, box as settled.
  ClusterObservation part = Obs({0.5, 0, 0.06});
  part.box_min = Eigen::Vector3d(0.45, -0.05, 0.05);
  part.box_max = Eigen::Vector3d(0.55, 0.05, 0.07);
  t.Update({part}, 3);
  ASSERT_EQ(t.tracks().size(), 1u);
  EXPECT_EQ(t.tracks()[0].cls, TrackClass::kStatic);
  EXPECT_NEAR(t.tracks()[0].mean_max.z(), 0.15, 1e-12);
  t.Update({Obs({0.5, 0, 0.1})}, 3);
  EXPECT_EQ(t.tracks()[0].cls, TrackClass::kStatic);
  // It moves 5 cm: a person (carried), same id.
  t.Update({Obs({0.55, 0, 0.1})}, 3);
  EXPECT_EQ(t.tracks()[0].cls, TrackClass::kHuman);
  EXPECT_EQ(t.tracks()[0].id, 1u);
  // A second cluster far away is a new track; a person-sized one is human at once.
  t.Update({Obs({0.55, 0, 0.1}), Obs({1.5, 0, 0.3}, 0.3)}, 4);
  ASSERT_EQ(t.tracks().size(), 2u);
  EXPECT_EQ(t.tracks()[1].id, 2u);
  EXPECT_EQ(t.tracks()[1].cls, TrackClass::kHuman);
  // Unseen for lost_frames + 1 frames: gone.
  for (int f = 5; f < 8; ++f) t.Update({}, f);
  EXPECT_TRUE(t.tracks().empty());
  EXPECT_THROW(ClusterTracker(TrackerParams{0}), std::invalid_argument);
}

// The arm in front of a static box splits what the camera sees of it in two
// (the case `camera_only_cell_test`'s standing person met: the second piece
// became a new, pending, so human, track 0.8 m from the person, judged at
// the ISO speed, and the robot stopped). Both pieces are the box; a cluster
// sticking out of its box (a hand over it) is not.
TEST(ClusterTrackerTest, AStaticObstacleSplitInTwoByTheArmStaysOneStaticObstacle) {
  TrackerParams p;
  p.static_frames = 3;
  ClusterTracker t(p);
  for (int f = 0; f < 3; ++f) t.Update({Obs({0.5, 0, 0.1})}, f);  // box [0.45, 0.55] x [-0.05, 0.05] x [0.05, 0.15]
  ASSERT_EQ(t.tracks().size(), 1u);
  ASSERT_EQ(t.tracks()[0].cls, TrackClass::kStatic);
  ClusterObservation left = Obs({0.47, 0, 0.1}), right = Obs({0.53, 0, 0.1});
  left.box_min.x() = 0.45;
  left.box_max.x() = 0.49;
  right.box_min.x() = 0.51;
  right.box_max.x() = 0.55;
  const std::vector<int> idx = t.Update({left, right}, 3);
  ASSERT_EQ(t.tracks().size(), 1u) << "a piece of the box started a track of its own";
  EXPECT_EQ(idx, (std::vector<int>{0, 0}));
  EXPECT_FALSE(t.IsHuman(t.tracks()[0]));
  EXPECT_EQ(t.tracks()[0].cls, TrackClass::kStatic);
  EXPECT_NEAR(t.tracks()[0].mean_min.x(), 0.45, 1e-12);  // the box as settled
  EXPECT_NEAR(t.tracks()[0].mean_max.x(), 0.55, 1e-12);
  // Beside the box's pieces, a cluster reaching 10 cm above it: a new track, human while pending.
  ClusterObservation hand = Obs({0.5, 0, 0.2});
  const std::vector<int> idx2 = t.Update({left, right, hand}, 4);
  ASSERT_EQ(t.tracks().size(), 2u);
  EXPECT_EQ(idx2[2], 1);
  EXPECT_TRUE(t.IsHuman(t.tracks()[1]));
  EXPECT_FALSE(t.IsHuman(t.tracks()[0]));
}

}  // namespace
}  // namespace iplan::cloud_service

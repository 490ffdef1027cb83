// SceneBuilder: the scene entities follow the robot model, the skeleton and
// the prediction, and inputs that do not fit the model are refused, counted.
#include "iplan/viewer/scene_builder.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

namespace iplan::viewer {
namespace {

const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config";

CellModel Model() {
  return LoadCellModel(kConfig + "/robots/panda.yaml", kConfig + "/scenes/cell.yaml", kConfig + "/humans/upper_body.yaml");
}

msg::JointState Joints(double q1) {
  msg::JointState js;
  js.header.frame_id = "world";
  for (int i = 1; i <= 7; ++i) {
    js.name.push_back("panda_joint" + std::to_string(i));
    js.position.push_back(i == 1 ? q1 : (i == 4 ? -1.5 : 0.0));
  }
  return js;
}

Eigen::Vector3d At(const nlohmann::json& sphere) {
  const auto& p = sphere["pose"]["position"];
  return {p["x"].get<double>(), p["y"].get<double>(), p["z"].get<double>()};
}

TEST(SceneBuilder, RobotSpheresFollowTheJoints) {
  SceneBuilder b(Model());
  const nlohmann::json a0 = *b.Robot(Joints(0.0));
  const auto* a = &a0;
  const auto* c = b.Robot(Joints(1.0));
  ASSERT_TRUE(a && c);
  const auto& ea = (*a)["entities"][0];
  EXPECT_EQ(ea["id"], entity::kRobot);
  EXPECT_EQ(ea["spheres"].size(), b.model().robot.spheres.size());
  ASSERT_FALSE(ea["spheres"].empty());
  // Joint 1 turns about the base's z axis: a sphere far out on the arm moves
  // on a circle, its height unchanged.
  const auto& last_a = ea["spheres"].back();
  const auto& last_c = (*c)["entities"][0]["spheres"].back();
  const Eigen::Vector3d pa = At(last_a), pc = At(last_c);
  EXPECT_NEAR(pa.z(), pc.z(), 1e-9);
  EXPECT_NEAR(pa.head<2>().norm(), pc.head<2>().norm(), 1e-9);
  EXPECT_NEAR(std::atan2(pc.y(), pc.x()) - std::atan2(pa.y(), pa.x()), 1.0, 1e-9);
  EXPECT_NEAR(last_a["size"]["x"].get<double>(), 2 * b.model().robot.spheres.back().radius, 1e-12);
  EXPECT_EQ(b.rejected(), 0u);
}

// Another arm from its URDF (mesh collision geometry): the viewer draws the
// spheres every check uses, where forward kinematics puts them.
TEST(SceneBuilder, DrawsTheUr5eFromItsUrdf) {
  SceneBuilder b(LoadCellModel(std::string(IPLAN_SHARED_DIR) + "/robots/ur5e/ur5e.urdf", kConfig + "/scenes/cell.yaml",
                               kConfig + "/humans/upper_body.yaml"));
  const collision::RobotModel& ur = b.model().robot;
  ASSERT_EQ(ur.nq, 6);
  msg::JointState js;
  js.header.frame_id = "world";
  js.name = ur.JointNames();
  js.position = {0.3, -1.2, 1.1, -1.5, -1.57, 0.2};
  const nlohmann::json* scene = b.Robot(js);
  ASSERT_NE(scene, nullptr) << b.last_rejection();
  const auto& spheres = (*scene)["entities"][0]["spheres"];
  ASSERT_EQ(spheres.size(), ur.spheres.size());
  collision::RobotData data(ur);
  collision::CalcForwardKinematics(ur, Eigen::Map<const Eigen::VectorXd>(js.position.data(), 6), &data);
  for (std::size_t i = 0; i < ur.spheres.size(); ++i) {
    EXPECT_LT((At(spheres[i]) - data.p_WS.col(static_cast<int>(i))).norm(), 1e-9) << i;
  }
  EXPECT_EQ(b.rejected(), 0u);
}

TEST(SceneBuilder, RefusesJointStatesThatDoNotFit) {
  SceneBuilder b(Model());
  msg::JointState js = Joints(0.0);
  js.name[3] = "elbow";
  EXPECT_FALSE(b.Robot(js));
  EXPECT_EQ(b.rejected(), 1u);
  EXPECT_NE(b.last_rejection().find("panda_joint4"), std::string::npos);
  js = Joints(0.0);
  js.position.pop_back();
  EXPECT_FALSE(b.Robot(js));
  EXPECT_EQ(b.rejected(), 2u);
}

TEST(SceneBuilder, PersonHasBonesAndBodySpheres) {
  SceneBuilder b(Model());
  msg::HumanSkeleton s;
  int k = 0;
  for (const auto& name : b.model().body.params().joints) {
    msg::HumanJoint j;
    j.name = name;
    j.position.x = 1.3;
    j.position.y = 0.1 * k;
    j.position.z = 0.2 + 0.05 * k++;
    s.joints.push_back(j);
  }
  const auto u = b.Person(s);
  ASSERT_TRUE(u);
  const auto& e = (*u)["entities"][0];
  EXPECT_EQ(e["spheres"].size(), static_cast<std::size_t>(b.model().body.num_spheres()));
  EXPECT_EQ(e["lines"][0]["points"].size(), 2 * b.model().body.params().segments.size());
  s.joints.pop_back();
  EXPECT_FALSE(b.Person(s));
  EXPECT_EQ(b.rejected(), 1u);
}

TEST(SceneBuilder, PredictionIsShadedByProbability) {
  SceneBuilder b(Model(), SceneBuilderOptions{2, 2, 1});
  msg::HumanPrediction p;
  p.joint_names = b.model().body.params().joints;
  p.num_steps = 5;
  for (double prob : {0.2, 0.7, 0.1}) {
    msg::ActionPrediction a;
    a.action = "a" + std::to_string(prob);
    a.probability = prob;
    a.joints.resize(p.num_steps * p.joint_names.size());
    p.actions.push_back(a);
  }
  const auto u = b.Prediction(p);
  ASSERT_TRUE(u);
  const auto& e = (*u)["entities"][0];
  const std::size_t per_pose = b.model().body.num_spheres();
  ASSERT_EQ(e["spheres"].size(), 2 * 2 * per_pose);  // two actions drawn, two steps each
  // Most probable first, and more opaque than the second.
  EXPECT_EQ(e["metadata"][0]["key"], "a0.700000");
  EXPECT_GT(e["spheres"][0]["color"]["a"].get<double>(), e["spheres"][2 * per_pose]["color"]["a"].get<double>());
  p.actions[0].joints.pop_back();
  EXPECT_FALSE(b.Prediction(p));
}

TEST(SceneBuilder, TrajectoryPathEndsAtTheLastWaypoint) {
  SceneBuilder b(Model(), SceneBuilderOptions{4, 3, 2});
  msg::JointTrajectory t;
  const msg::JointState a = Joints(0.0), c = Joints(0.8);
  t.joint_names = a.name;
  for (int k = 0; k <= 4; ++k) {
    msg::JointTrajectoryPoint pt;
    for (int i = 0; i < 7; ++i) pt.positions.push_back(a.position[i] + (c.position[i] - a.position[i]) * k / 4.0);
    t.points.push_back(pt);
  }
  const auto u1 = b.Trajectory(t);
  ASSERT_TRUE(u1);
  const auto& e1 = (*u1)["entities"][0];
  ASSERT_EQ(e1["lines"].size(), 1u);  // no previous plan yet
  EXPECT_EQ(e1["lines"][0]["points"].size(), 5u);
  EXPECT_EQ(e1["spheres"].size(), 2 * b.model().robot.spheres.size());  // two ghost poses
  const auto u2 = b.Trajectory(t);
  EXPECT_EQ((*u2)["entities"][0]["lines"].size(), 2u);  // the previous plan, faded, and the new one
}

// Updates are written in place into the builder's kept entity: the result
// must equal what a fresh builder makes of the same input.
TEST(SceneBuilder, InPlaceUpdatesEqualFreshOnes) {
  SceneBuilder kept(Model()), fresh(Model());
  kept.Robot(Joints(0.3));
  EXPECT_EQ(*kept.Robot(Joints(-0.7)), *fresh.Robot(Joints(-0.7)));
  msg::HumanPrediction p;
  p.joint_names = kept.model().body.params().joints;
  p.num_steps = 4;
  for (double prob : {0.5, 0.3, 0.2}) {
    msg::ActionPrediction a;
    a.action = "a" + std::to_string(prob);
    a.probability = prob;
    a.joints.resize(p.num_steps * p.joint_names.size());
    for (std::size_t i = 0; i < a.joints.size(); ++i) a.joints[i].mean.x = prob + 0.01 * i;
    p.actions.push_back(a);
  }
  kept.Prediction(p);
  p.actions.pop_back();  // fewer spheres than before
  p.actions[0].probability = 0.1;  // order and shading change
  SceneBuilder fresh2(Model());
  EXPECT_EQ(*kept.Prediction(p), *fresh2.Prediction(p));
}

msg::PointCloud2 Cloud(const std::vector<Eigen::Vector3f>& points) {
  msg::PointCloud2 c;
  c.header.frame_id = "world";
  c.height = 1;
  c.width = static_cast<uint32_t>(points.size());
  c.point_step = 16;  // x y z + 4 bytes of something else
  c.row_step = c.point_step * c.width;
  for (const char* n : {"x", "y", "z"}) {
    msg::PointField f;
    f.name = n;
    f.offset = static_cast<uint32_t>(4 * c.fields.size());
    f.datatype = msg::PointField::FLOAT32;
    f.count = 1;
    c.fields.push_back(f);
  }
  c.data.resize(c.row_step);
  for (std::size_t i = 0; i < points.size(); ++i) std::memcpy(&c.data[i * 16], points[i].data(), 12);
  return c;
}

TEST(SceneBuilder, ObstaclePointsBecomeCubes) {
  SceneBuilderOptions o;
  o.max_cloud_points = 2;
  SceneBuilder b(Model(), o);
  const float nan = std::nanf("");
  // Four points, at most two drawn: every second one, points 0 and 2.
  const auto* u = b.Obstacles(Cloud({{0.1f, 0.2f, 0.3f}, {9, 9, 9}, {1, 2, 3}, {4, 5, 6}}));
  ASSERT_TRUE(u);
  ASSERT_EQ((*u)["entities"][0]["cubes"].size(), 2u);
  EXPECT_NEAR(At((*u)["entities"][0]["cubes"][0]).z(), 0.3, 1e-6);
  EXPECT_NEAR(At((*u)["entities"][0]["cubes"][1]).x(), 1.0, 1e-6);
  // A point that is not finite is skipped.
  u = b.Obstacles(Cloud({{0.1f, 0.2f, 0.3f}, {9, 9, 9}, {nan, 0, 0}, {4, 5, 6}}));
  ASSERT_EQ((*u)["entities"][0]["cubes"].size(), 1u);
  msg::PointCloud2 bad = Cloud({{0, 0, 0}});
  bad.fields[2].datatype = msg::PointField::FLOAT64;
  EXPECT_FALSE(b.Obstacles(bad));
  bad = Cloud({{0, 0, 0}});
  bad.header.frame_id = "camera";
  EXPECT_FALSE(b.Obstacles(bad));
  bad = Cloud({{0, 0, 0}, {1, 1, 1}});
  bad.data.resize(20);
  EXPECT_FALSE(b.Obstacles(bad));
  EXPECT_EQ(b.rejected(), 3u);
}

// Issue 29: the cloud service's boxes and the person's points.
TEST(SceneBuilder, CloudBoxesAndHumanPointsAreDrawn) {
  SceneBuilder b(Model());
  msg::ObstacleArray a;
  a.header.frame_id = "world";
  msg::Obstacle o;
  o.id = 3;
  o.centre.x = 0.5;
  o.centre.y = -0.2;
  o.centre.z = 0.1;
  o.orientation.z = std::sin(0.15);  // turned 0.3 rad about z
  o.orientation.w = std::cos(0.15);
  o.half_extents = {0.05, 0.1, 0.15};
  a.obstacles.push_back(o);
  const auto* u = b.Boxes(a);
  ASSERT_TRUE(u);
  const auto& box = (*u)["entities"][0]["cubes"][0];
  EXPECT_EQ((*u)["entities"][0]["id"], entity::kBoxes);
  EXPECT_NEAR(At(box).y(), -0.2, 1e-12);
  EXPECT_DOUBLE_EQ(box["size"]["z"].get<double>(), 0.3);
  EXPECT_DOUBLE_EQ(box["size"]["y"].get<double>(), 0.2);  // along the box's own y
  EXPECT_DOUBLE_EQ(box["pose"]["orientation"]["z"].get<double>(), std::sin(0.15));
  EXPECT_DOUBLE_EQ(box["pose"]["orientation"]["w"].get<double>(), std::cos(0.15));
  // Three points: two of a part moving at 1 m/s along -x, one not tracked.
  msg::HumanPoints p;
  p.header.frame_id = "world";
  p.voxel_size = 0.03;
  for (int i = 0; i < 3; ++i) {
    msg::PointGaussian g;
    g.mean.x = 1.0 + 0.1 * i;
    g.mean.z = 1.0;
    g.motion = i < 2 ? 1 : 0;
    p.points.push_back(g);
  }
  msg::PointMotion m;
  m.id = 7;
  m.velocity.x = -1.0;
  p.motions.push_back(m);
  u = b.HumanPoints(p);
  ASSERT_TRUE(u);
  const auto& e = (*u)["entities"][0];
  ASSERT_EQ(e["cubes"].size(), 3u);
  EXPECT_DOUBLE_EQ(e["cubes"][0]["size"]["x"].get<double>(), 0.03);
  EXPECT_NE(e["cubes"][0]["color"], e["cubes"][2]["color"]);  // tracked vs not
  EXPECT_EQ(e["cubes"][0]["color"], e["cubes"][1]["color"]);
  // The part's velocity: from its centroid (1.05, 0, 1) to 0.5 s ahead.
  ASSERT_EQ(e["lines"].size(), 1u);
  ASSERT_EQ(e["lines"][0]["points"].size(), 2u);
  EXPECT_NEAR(e["lines"][0]["points"][0]["x"].get<double>(), 1.05, 1e-12);
  EXPECT_NEAR(e["lines"][0]["points"][1]["x"].get<double>(), 0.55, 1e-12);
  p.header.frame_id = "camera";
  EXPECT_FALSE(b.HumanPoints(p));
  a.header.frame_id = "camera";
  EXPECT_FALSE(b.Boxes(a));
  EXPECT_EQ(b.rejected(), 2u);
}

TEST(SceneBuilder, StaticSceneHasEveryObject) {
  SceneBuilder b(Model());
  const auto u = b.Static(msg::Time{});
  const auto& e = u["entities"][0];
  EXPECT_EQ(e["cubes"].size() + e["cylinders"].size(), b.model().scene.objects.size());
  EXPECT_EQ(e["cylinders"].size(), 1u);  // the pillar
}

}  // namespace
}  // namespace iplan::viewer

// Unit tests of the generated message layer: JSON round trips, field-by-field
// comparison, finiteness and consistency checks.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "iplan/msg/check.h"
#include "iplan/msg/json.h"
#include "iplan/msg/time.h"
#include "iplan/msg/type_table.h"

namespace iplan::msg {
namespace {

HumanSkeleton MakeSkeleton() {
  HumanSkeleton s;
  s.header.stamp = TimeFromSeconds(1700000000.25);
  s.header.frame_id = "world";
  s.body_id = 3;
  s.confidence = 0.9;
  for (const char* name : {"head", "torso", "hand_r"}) {
    HumanJoint j;
    j.name = name;
    j.position.x = 0.1;
    j.position.y = -0.2;
    j.position.z = 1.3;
    j.covariance = {1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4};
    j.confidence = 1.0;
    s.joints.push_back(j);
  }
  return s;
}

TEST(MsgJson, EveryTypeRoundTripsThroughJson) {
  for (const auto& entry : AllTypes()) {
    for (uint64_t seed = 1; seed <= 5; ++seed) {
      void* a = entry.create();
      void* b = entry.create();
      entry.randomize(a, seed);
      entry.from_json(entry.to_json(a), b);
      EXPECT_EQ(entry.first_difference(a, b), std::nullopt) << entry.dds_name;
      entry.destroy(a);
      entry.destroy(b);
    }
  }
}

TEST(MsgJson, RandomFillIsSeededAndDiffers) {
  const TypeEntry* e = FindType("HumanPrediction");
  ASSERT_NE(e, nullptr);
  void* a = e->create();
  void* b = e->create();
  e->randomize(a, 42);
  e->randomize(b, 42);
  EXPECT_EQ(e->first_difference(a, b), std::nullopt);
  e->randomize(b, 43);
  EXPECT_NE(e->first_difference(a, b), std::nullopt);
  e->destroy(a);
  e->destroy(b);
}

TEST(MsgJson, RandomSkeletonRoundTripsBitExactly) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 50; ++i) {
    HumanPrediction p;
    FillRandom(p, rng);
    HumanPrediction q;
    FromJson(ToJson(p), &q);
    EXPECT_EQ(FirstDifference(p, q), std::nullopt);
  }
}

TEST(MsgJson, NonFiniteNumbersAreWrittenAsStrings) {
  HumanSkeleton s = MakeSkeleton();
  s.joints[1].position.y = std::numeric_limits<double>::quiet_NaN();
  s.joints[2].position.z = -std::numeric_limits<double>::infinity();
  const nlohmann::json j = ToJson(s);
  EXPECT_EQ(j["joints"][1]["position"]["y"], "nan");
  EXPECT_EQ(j["joints"][2]["position"]["z"], "-inf");
  HumanSkeleton back;
  FromJson(j, &back);
  EXPECT_TRUE(std::isnan(back.joints[1].position.y));
  EXPECT_EQ(FirstDifference(s, back), std::nullopt);
}

TEST(MsgJson, UnknownFieldAndWrongTypeAreNamed) {
  HumanSkeleton s;
  try {
    FromJson(nlohmann::json::parse(R"({"body_idd": 3})"), &s);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown field 'body_idd'"), std::string::npos) << e.what();
  }
  try {
    FromJson(nlohmann::json::parse(R"({"joints": [{"position": {"x": "far"}}]})"), &s);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("joints[0].position.x"), std::string::npos) << e.what();
  }
  try {
    FromJson(nlohmann::json::parse(R"({"body_id": -1})"), &s);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
}

TEST(MsgCompare, FirstDifferenceNamesThePath) {
  HumanSkeleton a = MakeSkeleton();
  HumanSkeleton b = a;
  EXPECT_EQ(FirstDifference(a, b), std::nullopt);
  b.joints[2].covariance[4] = 2e-4;
  ASSERT_TRUE(FirstDifference(a, b).has_value());
  EXPECT_EQ(FirstDifference(a, b)->rfind("joints[2].covariance[4]", 0), 0u) << *FirstDifference(a, b);
  b = a;
  b.joints.pop_back();
  EXPECT_EQ(*FirstDifference(a, b), "joints: length 3 != 2");
}

TEST(MsgCheck, AcceptsAConsistentSkeleton) { EXPECT_EQ(Check(MakeSkeleton()), std::nullopt); }

TEST(MsgCheck, RejectsNonFiniteWithPath) {
  HumanSkeleton s = MakeSkeleton();
  s.joints[2].position.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(Check(s), std::string("non-finite number at joints[2].position.x"));
}

TEST(MsgCheck, RejectsDuplicateJointsAndBadCovariance) {
  HumanSkeleton s = MakeSkeleton();
  s.joints[1].name = "head";
  EXPECT_EQ(Check(s), std::string("joints[1]: joint 'head' appears twice"));
  s = MakeSkeleton();
  s.joints[0].covariance[1] = 1.0;  // not symmetric
  ASSERT_TRUE(Check(s).has_value());
  EXPECT_NE(Check(s)->find("not symmetric"), std::string::npos);
  s = MakeSkeleton();
  s.joints[0].covariance[0] = -1.0;
  EXPECT_NE(Check(s)->find("negative variance"), std::string::npos);
}

TEST(MsgCheck, RejectsWrongSizes) {
  JointState js;
  js.name = {"a", "b", "c"};
  js.position = {1, 2};
  EXPECT_EQ(Check(js), std::string("position has 2 entries for 3 names"));
  js.position = {1, 2, 3};
  EXPECT_EQ(Check(js), std::nullopt);

  HumanPrediction p;
  p.time_step = 1.0 / 15;
  p.num_steps = 2;
  p.joint_names = {"a", "b"};
  ActionPrediction a;
  a.action = "reach";
  a.probability = 1.0;
  a.joints.resize(3);
  p.actions.push_back(a);
  ASSERT_TRUE(Check(p).has_value());
  EXPECT_NE(Check(p)->find("expected 2 steps x 2 joints = 4"), std::string::npos) << *Check(p);
  p.actions[0].joints.resize(4);
  EXPECT_EQ(Check(p), std::nullopt);
}

TEST(MsgCheck, RejectsBeliefThatDoesNotSumToOne) {
  ActionBelief b;
  b.actions = {"a", "b"};
  b.probabilities = {0.5, 0.6};
  EXPECT_EQ(Check(b), std::string("probabilities sum to 1.1"));
}

TEST(MsgCheck, ObstacleOrientationMustBeAUnitQuaternion) {
  ObstacleArray a;
  a.header.frame_id = "world";
  Obstacle o;
  o.id = 1;
  o.half_extents = {0.1, 0.05, 0.1};
  o.orientation.z = std::sin(0.15);  // yaw 0.3 rad
  o.orientation.w = std::cos(0.15);
  a.obstacles.push_back(o);
  EXPECT_EQ(Check(a), std::nullopt);
  a.obstacles[0].orientation = {};  // all zero: no rotation at all
  EXPECT_EQ(Check(a), std::string("obstacles[0].orientation is not a unit quaternion (norm 0)"));
  a.obstacles[0].orientation.w = 1.01;
  ASSERT_TRUE(Check(a).has_value());
  EXPECT_NE(Check(a)->find("norm 1.01"), std::string::npos) << *Check(a);
}

// Size limits: each at the limit passes, one above is rejected naming the
// field and the limit (Limits in check.h).

// `n` skeleton joints with distinct names and valid numbers.
HumanSkeleton SkeletonWithJoints(std::size_t n) {
  HumanSkeleton s = MakeSkeleton();
  s.joints.resize(n, s.joints[0]);
  for (std::size_t i = 0; i < n; ++i) s.joints[i].name = "j" + std::to_string(i);
  return s;
}

// A consistent prediction of the given shape.
HumanPrediction PredictionOf(std::size_t actions, uint32_t steps, std::size_t joints) {
  HumanPrediction p;
  p.time_step = 1.0 / 15;
  p.num_steps = steps;
  for (std::size_t j = 0; j < joints; ++j) p.joint_names.push_back("j" + std::to_string(j));
  for (std::size_t a = 0; a < actions; ++a) {
    ActionPrediction act;
    act.action = "a" + std::to_string(a);
    act.probability = 1.0 / static_cast<double>(actions);
    act.joints.resize(std::size_t{steps} * joints);
    for (auto& g : act.joints) g.covariance = {1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 1e-4};
    p.actions.push_back(std::move(act));
  }
  return p;
}

std::vector<std::string> Names(std::size_t n) {
  std::vector<std::string> v;
  for (std::size_t i = 0; i < n; ++i) v.push_back("joint" + std::to_string(i));
  return v;
}

TEST(MsgLimits, SkeletonJoints) {
  EXPECT_EQ(Check(SkeletonWithJoints(Limits::kSkeletonJoints)), std::nullopt);
  EXPECT_EQ(Check(SkeletonWithJoints(Limits::kSkeletonJoints + 1)), std::string("joints has 129 entries, limit 128"));
}

TEST(MsgLimits, TwentyThousandJointSkeletonIsRejectedBySize) {
  // The size is refused before any per-joint work (formerly an O(n^2)
  // duplicate search); even a NaN in the last joint is not looked at.
  HumanSkeleton s = SkeletonWithJoints(20000);
  s.joints.back().position.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(Check(s), std::string("joints has 20000 entries, limit 128"));
  // CheckSemantics on its own refuses it too, before its duplicate search.
  EXPECT_EQ(CheckSemantics(SkeletonWithJoints(20000)), std::string("joints has 20000 entries, limit 128"));
}

TEST(MsgLimits, DuplicateJointNamesAmongManyAreFound) {
  HumanSkeleton s = SkeletonWithJoints(Limits::kSkeletonJoints);
  s.joints[100].name = "j7";
  s.joints[50].name = "j90";
  // The first joint, in message order, whose name came earlier.
  EXPECT_EQ(Check(s), std::string("joints[90]: joint 'j90' appears twice"));
}

TEST(MsgLimits, StringLengths) {
  HumanSkeleton s = MakeSkeleton();
  s.header.frame_id = std::string(Limits::kName, 'w');
  s.joints[1].name = std::string(Limits::kName, 'n');
  EXPECT_EQ(Check(s), std::nullopt);
  s.header.frame_id += "w";
  EXPECT_EQ(Check(s), std::string("header.frame_id has 257 characters, limit 256"));
  s.header.frame_id.pop_back();
  s.joints[1].name += "n";
  EXPECT_EQ(Check(s), std::string("joints[1].name has 257 characters, limit 256"));

  TaskCommand c;
  c.command = TaskCommand::CANCEL;
  c.task_name = std::string(Limits::kName, 't');
  EXPECT_EQ(Check(c), std::nullopt);
  c.task_name += "t";
  EXPECT_EQ(Check(c), std::string("task_name has 257 characters, limit 256"));

  TaskOutcome o;
  o.reason = std::string(Limits::kText, 'r');
  EXPECT_EQ(Check(o), std::nullopt);
  o.reason += "r";
  EXPECT_EQ(Check(o), std::string("reason has 4097 characters, limit 4096"));

  SafetyPermit sc;
  sc.validity = 0.2;
  sc.source = std::string(Limits::kName, 's');
  EXPECT_EQ(Check(sc), std::nullopt);
  sc.source += "s";
  EXPECT_EQ(Check(sc), std::string("source has 257 characters, limit 256"));

  CollisionRisk r;
  r.max_robot_link = std::string(Limits::kName + 1, 'l');
  EXPECT_EQ(Check(r), std::string("max_robot_link has 257 characters, limit 256"));

  // A type without size rules of its own (a new message) still has its header checked.
  struct NewMessage {
    Header header;
  } n;
  n.header.frame_id = std::string(Limits::kName + 1, 'w');
  EXPECT_EQ(CheckSizes(n), std::string("header.frame_id has 257 characters, limit 256"));
}

TEST(MsgLimits, JointStateNamesAndValues) {
  JointState js;
  js.name = Names(Limits::kRobotJoints);
  js.position.assign(Limits::kRobotJoints, 0.0);
  js.velocity.assign(Limits::kRobotJoints, 0.0);
  EXPECT_EQ(Check(js), std::nullopt);
  js.name = Names(Limits::kRobotJoints + 1);
  EXPECT_EQ(Check(js), std::string("name has 65 entries, limit 64"));
  js.name = Names(Limits::kRobotJoints);
  js.velocity.assign(Limits::kRobotJoints + 1, 0.0);
  EXPECT_EQ(Check(js), std::string("velocity has 65 entries, limit 64"));
  js.velocity.clear();
  js.name[3] = std::string(Limits::kName + 1, 'x');
  EXPECT_EQ(Check(js), std::string("name[3] has 257 characters, limit 256"));
}

TEST(MsgLimits, TrajectoryJointsAndPoints) {
  JointTrajectory t;
  t.joint_names = Names(Limits::kRobotJoints);
  t.points.resize(Limits::kTrajectoryPoints);
  for (std::size_t i = 0; i < t.points.size(); ++i) {
    t.points[i].positions.assign(Limits::kRobotJoints, 0.0);
    t.points[i].time_from_start.nanosec = static_cast<uint32_t>(i * 1000);
  }
  EXPECT_EQ(Check(t), std::nullopt);
  t.points[5].effort.assign(Limits::kRobotJoints + 1, 0.0);
  EXPECT_EQ(Check(t), std::string("points[5].effort has 65 entries, limit 64"));
  t.points[5].effort.clear();
  t.points.push_back(t.points.back());
  EXPECT_EQ(Check(t), std::string("points has 2001 entries, limit 2000"));
  t.points.pop_back();
  t.joint_names = Names(Limits::kRobotJoints + 1);
  EXPECT_EQ(Check(t), std::string("joint_names has 65 entries, limit 64"));
}

TEST(MsgLimits, TaskCommandPositions) {
  TaskCommand c;
  c.goal_positions.assign(Limits::kRobotJoints, 0.0);
  c.retreat_positions.assign(Limits::kRobotJoints, 0.0);
  EXPECT_EQ(Check(c), std::nullopt);
  c.retreat_positions.push_back(0.0);
  EXPECT_EQ(Check(c), std::string("retreat_positions has 65 entries, limit 64"));
}

TEST(MsgLimits, BeliefActions) {
  ActionBelief b;
  b.actions = Names(Limits::kActions);
  b.probabilities.assign(Limits::kActions, 1.0 / Limits::kActions);
  EXPECT_EQ(Check(b), std::nullopt);
  b.actions = Names(Limits::kActions + 1);
  EXPECT_EQ(Check(b), std::string("actions has 33 entries, limit 32"));
  b.actions = Names(Limits::kActions);
  b.probabilities.assign(Limits::kActions + 1, 0.0);
  EXPECT_EQ(Check(b), std::string("probabilities has 33 entries, limit 32"));
}

TEST(MsgLimits, PredictionShape) {
  EXPECT_EQ(Check(PredictionOf(1, Limits::kPredictionSteps, 1)), std::nullopt);
  EXPECT_EQ(Check(PredictionOf(1, Limits::kPredictionSteps + 1, 1)), std::string("num_steps is 201, limit 200"));
  EXPECT_EQ(Check(PredictionOf(1, 1, Limits::kPredictionJoints)), std::nullopt);
  EXPECT_EQ(Check(PredictionOf(1, 1, Limits::kPredictionJoints + 1)), std::string("joint_names has 129 entries, limit 128"));
  EXPECT_EQ(Check(PredictionOf(Limits::kActions, 1, 1)), std::nullopt);
  EXPECT_EQ(Check(PredictionOf(Limits::kActions + 1, 1, 1)), std::string("actions has 33 entries, limit 32"));
  // Each factor within its limit, the product not: 8 x 64 x 128 = 65536 fits, 8 x 65 x 128 does not.
  EXPECT_EQ(Check(PredictionOf(8, 64, 128)), std::nullopt);
  EXPECT_EQ(Check(PredictionOf(8, 65, 128)),
            std::string("actions x num_steps x joint_names = 66560 Gaussians, limit 65536"));
  // A wire value of num_steps near 2^32 is refused before any product is formed.
  HumanPrediction p = PredictionOf(1, 1, 2);
  p.num_steps = std::numeric_limits<uint32_t>::max();
  EXPECT_EQ(Check(p), std::string("num_steps is 4294967295, limit 200"));
  // Sent Gaussians beyond the limit are refused before they are walked,
  // whatever is declared.
  p = PredictionOf(1, 1, 1);
  p.actions[0].joints.resize(Limits::kPredictionGaussians + 1);
  EXPECT_EQ(Check(p), std::string("actions[].joints has 65537 entries, limit 65536"));
}

TEST(MsgLimits, PointCloud) {
  PointCloud2 c;
  c.width = 640 * 4;
  c.height = 480;
  c.point_step = 16;
  c.row_step = c.point_step * c.width;
  EXPECT_EQ(CheckSizes(c), std::nullopt);  // 19 MB of data not needed for the size rules
  c.height = 481;
  EXPECT_EQ(Check(c), std::string("width x height = 1231360 points, limit 1228800"));
  c.height = 1;
  c.width = 1;
  c.point_step = Limits::kCloudPointStep;
  c.row_step = c.point_step;
  c.data.resize(c.row_step);
  EXPECT_EQ(Check(c), std::nullopt);
  c.point_step = Limits::kCloudPointStep + 1;
  EXPECT_EQ(Check(c), std::string("point_step is 257 bytes, limit 256"));
  c.point_step = 16;
  c.width = 1;
  c.data.resize(Limits::kCloudBytes);
  c.row_step = static_cast<uint32_t>(Limits::kCloudBytes);
  EXPECT_EQ(Check(c), std::nullopt);
  c.data.push_back(0);
  EXPECT_EQ(Check(c), std::string("data has 67108865 bytes, limit 67108864"));
}

TEST(MsgLimits, DepthImage) {
  Image im;
  im.width = 640;
  im.height = 480;
  im.encoding = "16UC1";
  im.step = 2 * im.width;
  im.data.resize(static_cast<std::size_t>(im.step) * im.height);
  EXPECT_EQ(Check(im), std::nullopt);
  im.data.pop_back();
  EXPECT_EQ(Check(im), std::string("data has 614399 bytes, expected step * height = 614400"));
  im.data.push_back(0);
  im.width = 640 * 4;
  im.height = 481;
  EXPECT_EQ(Check(im), std::string("width x height = 1231360 pixels, limit 1228800"));
  im.width = 640;
  im.height = 480;
  im.encoding = std::string(Limits::kName + 1, 'e');
  EXPECT_EQ(Check(im), std::string("encoding has 257 characters, limit 256"));
  im.encoding = "16UC1";
  im.height = 1;
  im.step = static_cast<uint32_t>(Limits::kImageBytes) + 1;
  im.data.resize(im.step);
  EXPECT_EQ(Check(im), std::string("data has 67108865 bytes, limit 67108864"));
}

TEST(MsgLimits, CameraInfo) {
  CameraInfo c;
  c.width = 640;
  c.height = 480;
  c.distortion_model = "plumb_bob";
  c.d.assign(5, 0.0);
  c.k = {525, 0, 319.5, 0, 525, 239.5, 0, 0, 1};
  EXPECT_EQ(Check(c), std::nullopt);
  c.d.assign(Limits::kDistortionCoefficients + 1, 0.0);
  EXPECT_EQ(Check(c), std::string("d has 33 entries, limit 32"));
  c.d.assign(5, 0.0);
  c.distortion_model = std::string(Limits::kName + 1, 'm');
  EXPECT_EQ(Check(c), std::string("distortion_model has 257 characters, limit 256"));
  c.distortion_model = "plumb_bob";
  c.k[2] = std::numeric_limits<double>::quiet_NaN();  // every number of every type: finite
  EXPECT_EQ(Check(c), std::string("non-finite number at k[2]"));
}

TEST(MsgLimits, Diagnostics) {
  DiagnosticArray a;
  a.status.resize(Limits::kDiagnosticStatuses);
  a.status[2].values.resize(Limits::kDiagnosticValues);
  a.status[2].values[7].value = std::string(Limits::kText, 'v');
  EXPECT_EQ(Check(a), std::nullopt);
  a.status[2].values[7].value += "v";
  EXPECT_EQ(Check(a), std::string("status[2].values[7].value has 4097 characters, limit 4096"));
  a.status[2].values[7].value.clear();
  a.status[2].values.emplace_back();
  EXPECT_EQ(Check(a), std::string("status[2].values has 257 entries, limit 256"));
  a.status[2].values.pop_back();
  a.status.emplace_back();
  EXPECT_EQ(Check(a), std::string("status has 65 entries, limit 64"));
}

TEST(MsgTime, NanosecondRoundTrip) {
  const Time t = TimeFromSeconds(1700000000.123456789);
  EXPECT_EQ(t.sec, 1700000000);
  EXPECT_NEAR(t.nanosec, 123456789u, 200u);
  EXPECT_EQ(ToNanoseconds(TimeFromNanoseconds(-1)), -1);
  EXPECT_EQ(TimeFromNanoseconds(-1).nanosec, 999999999u);
}

TEST(MsgTypeTable, FindsByDdsAndCppName) {
  ASSERT_NE(FindType("sensor_msgs::msg::dds_::JointState_"), nullptr);
  EXPECT_STREQ(FindType("JointState")->dds_name, "sensor_msgs::msg::dds_::JointState_");
  EXPECT_EQ(FindType("NoSuchType"), nullptr);
}

}  // namespace
}  // namespace iplan::msg

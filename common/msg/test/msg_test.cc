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

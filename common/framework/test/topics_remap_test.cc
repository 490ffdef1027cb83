// ROS 2-style remapping of the topic catalogue (topics.h): the rule syntax,
// what is refused, and that every catalogue function and the node's
// entitled-writer lookup follow a remapping.
#include <gtest/gtest.h>

#include "iplan/framework/topics.h"

namespace iplan::framework {
namespace {

class Remap : public ::testing::Test {
 protected:
  void TearDown() override { EXPECT_EQ(topics::SetRemappings({}), ""); }
};

TEST_F(Remap, ParsesRos2RulesAndQualifiesRelativeNames) {
  std::string from, to, error;
  ASSERT_TRUE(topics::ParseRemapRule("/iplan/robot/trajectory:=/arm_controller/joint_trajectory", &from, &to, &error))
      << error;
  EXPECT_EQ(from, "/iplan/robot/trajectory");
  EXPECT_EQ(to, "/arm_controller/joint_trajectory");
  ASSERT_TRUE(topics::ParseRemapRule("joint_states:=robot/joint_states", &from, &to, &error)) << error;
  EXPECT_EQ(from, "/joint_states");
  EXPECT_EQ(to, "/robot/joint_states");
}

TEST_F(Remap, RefusesMalformedRules) {
  std::string from, to, error;
  for (const std::string bad : {"/joint_states", "/joint_states:=", ":=/x", "/a:=/b:=/c", "/joint_states:=/a//b",
                                "/joint_states:=/a/", "/joint_states:=/a b", "/joint_states:=/1abc"}) {
    error.clear();
    EXPECT_FALSE(topics::ParseRemapRule(bad, &from, &to, &error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
  EXPECT_FALSE(topics::ParseRemapRule("/joint_states:=/a-b", &from, &to, &error));
  EXPECT_EQ(error, "remap '/joint_states:=/a-b': '/a-b' has '-' (allowed: A-Z a-z 0-9 _ /)");
}

TEST_F(Remap, CatalogueFunctionsReturnTheRemappedName) {
  ASSERT_EQ(topics::SetRemappings({{"/iplan/robot/trajectory", "/arm_controller/joint_trajectory"},
                                   {"/joint_states", "/robot/joint_states"}}),
            "");
  EXPECT_EQ(topics::RobotTrajectory().name, "rt/arm_controller/joint_trajectory");
  EXPECT_EQ(topics::JointStates().name, "rt/robot/joint_states");
  EXPECT_EQ(topics::TaskCommand().name, "rt/iplan/task/command");  // not remapped
  // QoS and entitled writers travel with the topic.
  EXPECT_EQ(topics::RobotTrajectory().writers, std::vector<std::string>{"iplan-trajopt"});
  EXPECT_EQ(topics::CatalogueName("rt/arm_controller/joint_trajectory"), "rt/iplan/robot/trajectory");
  EXPECT_EQ(topics::CatalogueName("rt/iplan/task/command"), "rt/iplan/task/command");
  int found = 0;
  for (const auto& d : topics::All()) found += d.name == "rt/arm_controller/joint_trajectory";
  EXPECT_EQ(found, 1);
  // Replacing the set undoes the old one.
  ASSERT_EQ(topics::SetRemappings({}), "");
  EXPECT_EQ(topics::RobotTrajectory().name, "rt/iplan/robot/trajectory");
}

TEST_F(Remap, RefusesUnknownTopicsAndCollisionsAndKeepsTheOldSet) {
  ASSERT_EQ(topics::SetRemappings({{"/joint_states", "/robot/joint_states"}}), "");
  const std::string unknown = topics::SetRemappings({{"/iplan/robot/trajectroy", "/x"}});
  EXPECT_EQ(unknown.rfind("remap: '/iplan/robot/trajectroy' is not a topic of the catalogue (", 0), 0u) << unknown;
  EXPECT_NE(unknown.find("/iplan/robot/trajectory"), std::string::npos) << unknown;
  EXPECT_EQ(topics::SetRemappings({{"/joint_states", "/iplan/task/command"}}),
            "remap: two topics would be named /iplan/task/command");
  EXPECT_EQ(topics::SetRemappings({{"/joint_states", "/a"}, {"/iplan/task/command", "/a"}}),
            "remap: two topics would be named /a");
  // A refused set changes nothing.
  EXPECT_EQ(topics::JointStates().name, "rt/robot/joint_states");
}

}  // namespace
}  // namespace iplan::framework

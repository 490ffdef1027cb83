// Task places given as tool poses, solved for the robot at hand
// (core/task_goals.h): the Panda keeps its hand-picked joint goals, the
// UR5e gets every place of the same cell file solved, bad places are named.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "services/supervisor/core/task_goals.h"
#include "services/supervisor/core/task_planner.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/scene.h"
#include "iplan/collision/self_collision.h"
#include "iplan/planning/planner_params.h"

namespace iplan::supervisor {
namespace {

const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config";

planning::Planner MakePlanner(const std::string& robot_file) {
  return planning::Planner(collision::LoadRobotModel(robot_file), collision::LoadSceneParams(kConfig + "/scenes/cell.yaml"),
                           planning::LoadPlannerParams(kConfig + "/planner_replanning.yaml"));
}

TaskGraph CellGraph() { return LoadTaskGraph(kConfig + "/tasks/table_top.yaml"); }

// End-effector position and z axis of `planner`'s robot at q.
std::pair<Eigen::Vector3d, Eigen::Vector3d> EndEffector(const planning::Planner& planner, const std::vector<double>& q) {
  const collision::RobotModel& robot = planner.robot();
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, Eigen::Map<const Eigen::VectorXd>(q.data(), robot.nq), &d);
  const Eigen::Isometry3d& X = d.X_WL[robot.FindLink(planner.params().end_effector_link)];
  return {X.translation(), X.linear().col(2)};
}

TEST(TaskGoals, PandaKeepsTheJointGoalsWrittenForIt) {
  const planning::Planner panda = MakePlanner(kConfig + "/robots/panda.yaml");
  const TaskGraph written = CellGraph();
  TaskGraph g = written;
  EXPECT_TRUE(ResolveTaskGoals(panda, &g).empty());
  for (std::size_t i = 0; i < g.tasks.size(); ++i) {
    EXPECT_EQ(g.tasks[i].goal, written.tasks[i].goal) << g.tasks[i].name;
    EXPECT_EQ(g.tasks[i].retreat, written.tasks[i].retreat) << g.tasks[i].name;
  }
  EXPECT_EQ(RestPositions(g), written.tasks.back().goal);  // rest: home
}

TEST(TaskGoals, Ur5eGetsEveryPlaceOfTheSameCellSolved) {
  const planning::Planner ur = MakePlanner(std::string(IPLAN_SHARED_DIR) + "/robots/ur5e/ur5e.urdf");
  TaskGraph g = CellGraph();
  const std::vector<std::string> notes = ResolveTaskGoals(ur, &g);
  EXPECT_EQ(notes.size(), 6u);  // five goals and the hand-over's retreat
  const std::vector<double> rest = RestPositions(g);
  ASSERT_EQ(rest.size(), 6u);
  const collision::SelfCollisionModel self = collision::ComputeSelfCollision(ur.robot());
  for (const RobotTask& t : g.tasks) {
    for (const auto& [q, pose] : {std::pair{&t.goal, &t.goal_pose}, std::pair{&t.retreat, &t.retreat_pose}}) {
      if (!pose->given()) continue;
      ASSERT_EQ(q->size(), 6u) << t.name;
      const auto [p, z] = EndEffector(ur, *q);
      EXPECT_LT((p - Eigen::Vector3d(pose->position[0], pose->position[1], pose->position[2])).norm(), 1e-3) << t.name;
      EXPECT_GT(z.dot(Eigen::Vector3d(0, 0, -1)), std::cos(1e-2)) << t.name;
      EXPECT_GE(ur.CalcClearance(Eigen::Map<const Eigen::VectorXd>(q->data(), 6)), 0.0) << t.name;
      collision::RobotData d(ur.robot());
      collision::CalcForwardKinematics(ur.robot(), Eigen::Map<const Eigen::VectorXd>(q->data(), 6), &d);
      EXPECT_GE(collision::SelfDistance(ur.robot(), self, d), -GoalOptions{}.self_overlap) << t.name;
      // One arm configuration family: no joint turns half a turn or more
      // from the rest place (no elbow or wrist flip on the way).
      for (int j = 0; j < 6; ++j) EXPECT_LT(std::abs((*q)[j] - rest[j]), M_PI) << t.name << " joint " << j;
    }
  }
  TaskGraph again = CellGraph();
  ResolveTaskGoals(ur, &again);
  for (std::size_t i = 0; i < g.tasks.size(); ++i) EXPECT_EQ(again.tasks[i].goal, g.tasks[i].goal);
}

TEST(TaskGoals, APoseWinsOverJointPositionsThatDoNotReachIt) {
  const planning::Planner panda = MakePlanner(kConfig + "/robots/panda.yaml");
  TaskGraph g = CellGraph();
  RobotTask& fetch = g.tasks[0];
  fetch.goal_pose.position = {0.5, 0.2, 0.4};  // not where its joint goal puts the flange
  const std::vector<std::string> notes = ResolveTaskGoals(panda, &g);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("task 'fetch_left' goal: the joint positions put the end effector"), std::string::npos) << notes[0];
  EXPECT_LT((EndEffector(panda, fetch.goal).first - Eigen::Vector3d(0.5, 0.2, 0.4)).norm(), 1e-3);
}

TEST(TaskGoals, PlacesThatCannotBeSolvedAreNamed) {
  const planning::Planner panda = MakePlanner(kConfig + "/robots/panda.yaml");
  auto error = [&](TaskGraph g) {
    try {
      ResolveTaskGoals(panda, &g);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  TaskGraph wrong_size = CellGraph();
  wrong_size.tasks[1].goal = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  wrong_size.tasks[1].goal_pose = {};
  EXPECT_NE(error(wrong_size).find("task 'fetch_right' goal: 6 joint positions, robot 'panda' has 7 joints"),
            std::string::npos);
  TaskGraph far = CellGraph();
  far.tasks[3].goal = {};
  far.tasks[3].goal_pose.position = {3.0, 0.0, 0.5};
  EXPECT_NE(error(far).find("task 'inspect' goal: robot 'panda' has no solution clear of the scene and of itself"), std::string::npos)
      << error(far);
  TaskGraph bad_axis = CellGraph();
  bad_axis.tasks[0].goal_pose.z_axis = {0.0, 0.0, 0.0};
  EXPECT_NE(error(bad_axis).find("task 'fetch_left': goal_pose: z_axis must be 3 finite numbers"), std::string::npos);
  TaskGraph no_goal = CellGraph();
  no_goal.tasks[0].goal = {};
  no_goal.tasks[0].goal_pose = {};
  EXPECT_NE(error(no_goal).find("task 'fetch_left' has no goal (give goal or goal_pose)"), std::string::npos);
  TaskGraph bad_rest = CellGraph();
  bad_rest.rest = "nap";
  EXPECT_NE(error(bad_rest).find("rest names unknown task 'nap'"), std::string::npos);
}

}  // namespace
}  // namespace iplan::supervisor

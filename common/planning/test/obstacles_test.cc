// Perceived obstacles (PlanningRequest::obstacles, e.g. the boxes of
// /iplan/obstacles) join the planner's scene: a box put in the robot's path
// on the table is planned around, verified independently with FCL.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "iplan/collision/static_scene.h"
#include "iplan/planning/planner.h"
#include "test_util.h"

namespace iplan::planning {
namespace {

using testing::DownOrientation;
using testing::Ready;

// A box standing on the table top (z = 0), centre (x, y), full edge lengths.
collision::SceneObject TableBox(double x, double y, const Eigen::Vector3d& size) {
  collision::SceneObject o;
  o.name = "box";
  o.shape = collision::SceneObject::Shape::kBox;
  o.X_WO.translation() = Eigen::Vector3d(x, y, 0.5 * size.z());
  o.size = size;
  return o;
}

class ObstaclesTest : public ::testing::Test {
 protected:
  ObstaclesTest() : robot_(testing::LoadPanda()), planner_(robot_, testing::LoadCell(), PlannerParams{}) {}

  // FCL's signed distance of every robot sphere to `box` at 10 substeps
  // per interval (linear interpolation): the smallest over the trajectory.
  double FclDistanceToBox(const Eigen::MatrixXd& Q, const collision::SceneObject& box) const {
    const collision::StaticScene scene(collision::SceneParams{{box}});
    collision::RobotData d(robot_);
    std::vector<double> radii;
    for (const auto& s : robot_.spheres) radii.push_back(s.radius);
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < Q.cols(); ++i) {
      for (int s = 0; s < (i + 1 < Q.cols() ? 10 : 1); ++s) {
        const Eigen::VectorXd q = i + 1 < Q.cols() ? Eigen::VectorXd(Q.col(i) + 0.1 * s * (Q.col(i + 1) - Q.col(i)))
                                                   : Eigen::VectorXd(Q.col(i));
        collision::CalcForwardKinematics(robot_, q, &d);
        best = std::min(best, scene.CalcMinimumDistance(d.p_WS, radii).distance);
      }
    }
    return best;
  }

  collision::RobotModel robot_;
  Planner planner_;
};

TEST_F(ObstaclesTest, ABoxInThePathOnTheTableIsPlannedAround) {
  // From the right of the table to the left at 0.30 m: the free path sweeps
  // the gripper through (0.45, -0.1).
  const std::optional<PlanningRequest> across = testing::AcrossTheTable(planner_);
  ASSERT_TRUE(across.has_value());
  PlanningRequest req = *across;
  const collision::SceneObject box = TableBox(0.45, -0.1, {0.12, 0.12, 0.32});
  const PlanningResult free_r = planner_.Plan(req);
  ASSERT_TRUE(free_r.success()) << free_r.reason;
  // The box is in the way of the plan that does not know it...
  EXPECT_LT(FclDistanceToBox(free_r.positions, box), -0.02);
  req.obstacles = {box};
  const PlanningResult r = planner_.Plan(req);
  ASSERT_TRUE(r.success()) << r.reason;
  EXPECT_EQ(r.positions.col(0), req.start_q);
  EXPECT_EQ(r.positions.col(r.positions.cols() - 1), req.goal.q);
  EXPECT_EQ(CheckLimits(robot_, r.positions, r.dt, Eigen::VectorXd()), "");
  // ...and no sphere penetrates it along the plan that does (FCL, 10x the
  // waypoint resolution), which keeps min_clearance at the waypoints' substeps.
  EXPECT_GE(FclDistanceToBox(r.positions, box), 0.0);
  EXPECT_GE(r.min_clearance, planner_.params().min_clearance);
  // The planner's clearance with the box agrees with FCL at the goal.
  EXPECT_NEAR(planner_.CalcClearance(req.goal.q, {box}),
              std::min(planner_.CalcClearance(req.goal.q), FclDistanceToBox(req.goal.q, box)), 1e-9);
}

TEST_F(ObstaclesTest, AStartInsideABoxMovesOutWithoutGoingDeeper) {
  // A box put down under the hand 2 cm into it (or reached by the frozen
  // prefix before it was seen): the robot may leave it, not stay stuck.
  const IkResult s = planner_.SolveIk({0.45, -0.1, 0.25}, DownOrientation(0.0), Ready(), 1);
  const IkResult g = planner_.SolveIk({0.40, 0.30, 0.45}, DownOrientation(0.0), Ready(), 1);
  ASSERT_TRUE(s.success && g.success);
  const double low = 0.1 + planner_.CalcClearance(s.q, {TableBox(0.45, -0.1, {0.12, 0.12, 0.1})});
  const collision::SceneObject box = TableBox(0.45, -0.1, {0.12, 0.12, low + 0.02});
  const double start_clearance = planner_.CalcClearance(s.q, {box});
  ASSERT_NEAR(start_clearance, -0.02, 0.005);
  PlanningRequest req;
  req.start_q = s.q;
  req.goal = Goal::Joint(g.q);
  req.obstacles = {box};
  const PlanningResult r = planner_.Plan(req);
  ASSERT_TRUE(r.success()) << r.reason;
  EXPECT_EQ(r.positions.col(0), req.start_q);
  EXPECT_GE(r.min_clearance, start_clearance - 1e-12);
  EXPECT_GE(FclDistanceToBox(r.positions, box), start_clearance - 0.005);
  EXPECT_GE(planner_.CalcClearance(r.positions.col(r.positions.cols() - 1), {box}), 0.0);
}

TEST_F(ObstaclesTest, AGoalInsideABoxIsReportedAndBadBoxesAreRejected) {
  const IkResult g = planner_.SolveIk({0.45, 0.15, 0.10}, DownOrientation(0.0), Ready(), 1);
  ASSERT_TRUE(g.success);
  PlanningRequest req;
  req.start_q = Ready();
  req.goal = Goal::Joint(g.q);
  req.obstacles = {TableBox(0.45, 0.15, {0.2, 0.2, 0.2})};
  const PlanningResult r = planner_.Plan(req);
  EXPECT_EQ(r.status, PlanStatus::kGoalInCollision) << r.reason;
  req.obstacles[0].size.x() = 0.0;
  try {
    planner_.Plan(req);
    FAIL() << "a box of zero size was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("obstacles: object 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace iplan::planning

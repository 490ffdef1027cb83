// The depth camera's person as the planner's prediction
// (core/points_prediction.h): coarse spheres that move at the tracked parts'
// velocities with growing covariance; and the replanner planning against
// them when no skeleton prediction exists: points on the goal hold the
// robot until they leave, points coming at the idle robot make it yield.
#include "services/trajopt/core/points_prediction.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "services/trajopt/core/replanner.h"
#include "iplan/planning/planner_params.h"
#include "replanner_fixture.h"

namespace iplan::trajopt {
namespace {

// Points on a sphere of radius r around c, about 3 cm apart, appended to
// `p` with motion `motion` (-1: not tracked), sensor noise (2 mm)^2.
void AddBall(cell::HumanPoints* p, const Eigen::Vector3d& c, double r, int motion) {
  const int n = std::max(8, static_cast<int>(4 * M_PI * r * r / (0.03 * 0.03)));
  const Eigen::Index old = p->means.cols();
  p->means.conservativeResize(3, old + n);
  for (int i = 0; i < n; ++i) {  // Fibonacci sphere
    const double z = 1 - 2 * (i + 0.5) / n, s = std::sqrt(1 - z * z), phi = i * M_PI * (3 - std::sqrt(5.0));
    p->means.col(old + i) = c + r * Eigen::Vector3d(s * std::cos(phi), s * std::sin(phi), z);
    p->covariances.push_back(4e-6 * Eigen::Matrix3d::Identity());
    p->motion_of.push_back(motion);
  }
}

TEST(PointsPrediction, TrackedSpheresMoveWithGrowingCovarianceUntrackedOnesStay) {
  cell::HumanPoints seen;
  seen.voxel_size = 0.03;
  seen.motions.push_back({Eigen::Vector3d(-0.4, 0, 0), 0.01 * Eigen::Matrix3d::Identity()});
  AddBall(&seen, {1.0, 0.0, 1.0}, 0.06, 0);    // a hand, tracked, coming at -x
  AddBall(&seen, {1.4, 0.3, 1.0}, 0.06, -1);   // something not tracked
  ASSERT_EQ(seen.Check(), std::nullopt);
  PointsPredictionParams params;  // 0.1 m grid, 0.1 s steps over 1.5 s, moving for 0.5 s
  const safety::SsmParams ssm;  // T_r + T_s = 0.4 s, 1.6 m/s default
  // The shipped default (as collision risk's): the tracked hand too stays
  // where seen, with the ISO 1.6 m/s as its speed allowance; its radius is
  // what was seen (the ball, 6 cm, and the point's 1.5 cm), not grown.
  EXPECT_FALSE(params.tracked_speeds);
  const std::optional<collision::HumanPrediction> untracked = BuildPointsPrediction(params, seen, ssm);
  ASSERT_TRUE(untracked.has_value());
  for (int l = 0; l < untracked->num_spheres(); ++l) {
    EXPECT_DOUBLE_EQ(untracked->speed_allowance(l), 1.6);
    EXPECT_LE(untracked->radius(l), 0.12 + 0.015 + 1e-9);
    EXPECT_NEAR((untracked->sphere(0, untracked->num_steps() - 1, l).mean - untracked->sphere(0, 0, l).mean).norm(), 0.0, 1e-12);
  }
  params.tracked_speeds = true;
  const std::optional<collision::HumanPrediction> hp = BuildPointsPrediction(params, seen, ssm);
  ASSERT_TRUE(hp.has_value());
  EXPECT_EQ(hp->num_actions(), 1);
  EXPECT_DOUBLE_EQ(hp->action_probability(0), 1.0);
  EXPECT_EQ(hp->num_steps(), 15);
  ASSERT_GE(hp->num_spheres(), 2);
  // Every point is inside the sphere of its own part and cell at step 0 less
  // the step's motion (0.1 s at 0.4 m/s).
  for (int i = 0; i < seen.size(); ++i) {
    const Eigen::Vector3d shift = seen.motion_of[static_cast<std::size_t>(i)] == 0 ? Eigen::Vector3d(-0.04, 0, 0)
                                                                                  : Eigen::Vector3d::Zero();
    double inside = std::numeric_limits<double>::infinity();
    for (int l = 0; l < hp->num_spheres(); ++l)
      inside = std::min(inside, (seen.means.col(i) + shift - hp->sphere(0, 0, l).mean).norm() - hp->radius(l));
    EXPECT_LE(inside, 1e-9) << "point " << i;
  }
  for (int l = 0; l < hp->num_spheres(); ++l) {
    const Eigen::Vector3d step0 = hp->sphere(0, 0, l).mean, step4 = hp->sphere(0, 4, l).mean,
                          last = hp->sphere(0, 14, l).mean;
    const double var0 = hp->sphere(0, 0, l).eigenvalues.maxCoeff(), var14 = hp->sphere(0, 14, l).eigenvalues.maxCoeff();
    if (step0.x() < 1.2) {  // the hand: 0.4 m/s until 0.5 s (step 4), then still; variance + t^2 0.01
      EXPECT_NEAR((step4 - step0).x(), -0.4 * 0.4, 1e-9);
      EXPECT_NEAR((last - step4).norm(), 0.0, 1e-9);
      EXPECT_NEAR(var14 - var0, (1.5 * 1.5 - 0.1 * 0.1) * 0.01, 1e-9);
      // The monitor's 2 sigma (0.2 m/s) is the speed allowance; the radius
      // covers the cell's points only.
      EXPECT_NEAR(hp->speed_allowance(l), 0.2, 1e-12);
      EXPECT_LE(hp->radius(l), 0.12 + 0.015 + 1e-9);
    } else {  // not tracked: where seen, the noise only; the ISO 1.6 m/s as the allowance
      EXPECT_NEAR((last - step0).norm(), 0.0, 1e-12);
      EXPECT_NEAR(var14, var0, 1e-15);
      EXPECT_LT(var0, 1e-5);
      EXPECT_DOUBLE_EQ(hp->speed_allowance(l), 1.6);
      EXPECT_LE(hp->radius(l), 0.12 + 0.015 + 1e-9);
    }
  }
  seen.means.resize(3, 0);
  seen.covariances.clear();
  seen.motion_of.clear();
  EXPECT_FALSE(BuildPointsPrediction(params, seen, ssm).has_value());  // nobody seen
}

TEST(PointsPrediction, ManySpheresCoarsenTheGrid) {
  cell::HumanPoints seen;
  seen.voxel_size = 0.03;
  AddBall(&seen, {1.2, 0.0, 0.9}, 0.45, -1);  // a person-sized ball: ~30 cells of 0.2 m on its surface
  PointsPredictionParams params;
  params.max_spheres = 10;
  const std::optional<collision::HumanPrediction> hp = BuildPointsPrediction(params, seen, safety::SsmParams{});
  ASSERT_TRUE(hp.has_value());
  EXPECT_LE(hp->num_spheres(), 10);
  params.max_spheres = 48;
  EXPECT_GT(BuildPointsPrediction(params, seen, safety::SsmParams{})->num_spheres(), 10);
  params.sphere_size = 0;
  EXPECT_EQ(params.Validate(), "human_points.sphere_size must be > 0 m");
}

class PointsReplannerTest : public ::testing::Test {
 protected:
  static Eigen::VectorXd Ready() { return ReplannerTest::Ready(); }
  // A still-standing tracked person: a torso-sized ball behind a hand-sized one at `hand`.
  static cell::HumanPoints PersonAt(int64_t t, const Eigen::Vector3d& hand, const Eigen::Vector3d& v) {
    cell::HumanPoints p;
    p.stamp_ns = t;
    p.voxel_size = 0.03;
    p.motions.push_back({v, 0.01 * Eigen::Matrix3d::Identity()});
    AddBall(&p, hand, 0.06, 0);
    AddBall(&p, hand + Eigen::Vector3d(0.45, 0.0, 0.1), 0.17, 0);
    return p;
  }
  // The cell's replanning planner (predict_ssm on), as the service plans.
  const std::unique_ptr<planning::Planner> predicting_ = ReplannerTest::PredictingPlanner();
  const planning::Planner& planner_ = *predicting_;
  collision::HumanBodyModel body_{collision::HumanBodyParams::DefaultUpperBody()};
  Replanner replanner_{planner_, body_, ReplannerParams{}};
};

// Points (no skeleton prediction) on the goal: the robot is held until the
// person walks away, then arrives.
TEST_F(PointsReplannerTest, PointsOnTheGoalHoldTheRobotUntilTheyLeave) {
  const Eigen::VectorXd goal = ReplannerTest::Goal();
  collision::RobotData data(planner_.robot());
  collision::CalcForwardKinematics(planner_.robot(), goal, &data);
  const Eigen::Vector3d goal_hand = data.X_WL.back().translation();
  int64_t t = 100 * kSec;
  const int64_t leaves = t + 25 * kSec / 10;
  Eigen::VectorXd q = Ready();
  ASSERT_EQ(replanner_.StartTask({8, "reach_blocked", planning::Goal::Joint(goal), 0}, t), std::nullopt);
  std::optional<TaskOutcome> outcome;
  int on_points = 0;
  for (int k = 0; k < 150 && !outcome; ++k) {
    const std::vector<double> qv(q.data(), q.data() + q.size());
    ASSERT_EQ(replanner_.UpdateRobotState(t, replanner_.joint_names(), qv, std::vector<double>(7, 0.0)), std::nullopt);
    const Eigen::Vector3d hand = t < leaves ? goal_hand : Eigen::Vector3d(1.8, 0.8, 1.0);
    ASSERT_EQ(replanner_.UpdateHumanPoints(PersonAt(t, hand, Eigen::Vector3d::Zero())), std::nullopt);
    on_points += replanner_.PlansOnPoints(t);
    const CycleResult c = replanner_.Cycle(t);
    if (c.planning_time > 0) {
      EXPECT_EQ(c.num_people, 1);
      EXPECT_EQ(c.prediction_t0_ns, t);  // the cloud's stamp
    }
    outcome = c.outcome;
    t += kSec / 10;
    if (c.publish) {
      const double s = std::clamp((t - c.start_ns) * 1e-9 / c.dt, 0.0, static_cast<double>(c.positions.cols() - 1));
      const int i = std::min(static_cast<int>(s), static_cast<int>(c.positions.cols()) - 2);
      q = c.positions.cols() > 1 ? Eigen::VectorXd(c.positions.col(i) + (s - i) * (c.positions.col(i + 1) - c.positions.col(i)))
                                 : Eigen::VectorXd(c.positions.col(0));
    }
  }
  ASSERT_TRUE(outcome.has_value()) << "no outcome in 15 s";
  EXPECT_EQ(outcome->status, TaskStatus::kSucceeded) << outcome->reason;
  EXPECT_GT(on_points, 0);
  EXPECT_GT(outcome->delay, 1.0);        // held while the person stood on the goal
  EXPECT_GT(outcome->duration, 2.5);     // it could not arrive before they left
  EXPECT_LT(outcome->max_collision_bound, 0.05);
}

// A skeleton prediction, when fresh, is what the cycle plans against; the
// points only stand in while none is.
TEST_F(PointsReplannerTest, PointsStandInOnlyWhileNoSkeletonPredictionIsFresh) {
  const int64_t t = 100 * kSec;
  ASSERT_EQ(replanner_.UpdateHumanPoints(PersonAt(t, {1.0, 0.0, 1.0}, Eigen::Vector3d::Zero())), std::nullopt);
  EXPECT_TRUE(replanner_.PlansOnPoints(t));
  EXPECT_FALSE(replanner_.PlansOnPoints(t + kSec));  // stale (0.5 s)
  collision::JointMixture m;
  m.t0_ns = t;
  m.time_step = 0.1;
  m.num_steps = 2;
  m.joint_names = body_.params().joints;
  m.actions = {"stand"};
  m.probabilities = {1.0};
  m.means.assign(1, std::vector<Eigen::Vector3d>(2 * m.joint_names.size(), Eigen::Vector3d(1.5, 0, 1)));
  m.covariances.assign(1, std::vector<Eigen::Matrix3d>(2 * m.joint_names.size(), 1e-3 * Eigen::Matrix3d::Identity()));
  ASSERT_EQ(replanner_.UpdatePrediction(m), std::nullopt);
  EXPECT_FALSE(replanner_.PlansOnPoints(t));
  cell::HumanPoints older = PersonAt(t - kSec, {1.0, 0.0, 1.0}, Eigen::Vector3d::Zero());
  EXPECT_EQ(replanner_.UpdateHumanPoints(older), "human points: older than the last ones");
}

}  // namespace
}  // namespace iplan::trajopt

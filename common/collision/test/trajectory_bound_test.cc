#include "iplan/collision/trajectory_bound.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "alloc_counter.h"

namespace iplan::collision {
namespace {

Eigen::Matrix3d RandomCovariance(std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> n01;
  Eigen::Quaterniond q(n01(*rng), n01(*rng), n01(*rng), n01(*rng));
  q.normalize();
  const double s_max = std::pow(0.02 + 0.15 * u01(*rng), 2);
  const double ratio = std::pow(10.0, 3.0 * u01(*rng));
  const Eigen::Vector3d s(s_max / ratio, s_max / std::pow(ratio, u01(*rng)), s_max);
  Eigen::Matrix3d S = q.toRotationMatrix() * s.asDiagonal() * q.toRotationMatrix().transpose();
  return 0.5 * (S + S.transpose());
}

struct Problem {
  HumanPrediction prediction;
  RobotSpheresTrajectory trajectory;
};

// A person walking past a robot whose spheres sweep through space.
Problem RandomProblem(std::mt19937_64* rng, int A, int T, int H, int S, int W) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<double> radii(H);
  std::vector<int> segments(H);
  for (int l = 0; l < H; ++l) {
    radii[l] = 0.05 + 0.1 * u01(*rng);
    segments[l] = l / 2;
  }
  Problem p{HumanPrediction(A, T, radii, segments), {}};
  double psum = 0.0;
  std::vector<double> w(A);
  for (int c = 0; c < A; ++c) psum += (w[c] = u01(*rng) + 0.05);
  for (int c = 0; c < A; ++c) p.prediction.set_action_probability(c, w[c] / psum);
  for (int c = 0; c < A; ++c) {
    const Eigen::Vector3d heading(std::cos(c), std::sin(c), 0.0);
    for (int t = 0; t < T; ++t) {
      for (int l = 0; l < H; ++l) {
        const Eigen::Vector3d mean = Eigen::Vector3d(0.8, 0.0, 0.3 + 0.1 * l) +
                                     0.05 * t * heading +
                                     0.05 * Eigen::Vector3d(u01(*rng), u01(*rng), u01(*rng));
        EXPECT_TRUE(p.prediction.SetSphere(c, t, l, mean, RandomCovariance(rng)));
      }
    }
  }
  p.prediction.UpdateSummaries();
  p.trajectory.radii.resize(S);
  p.trajectory.links.resize(S);
  for (int k = 0; k < S; ++k) {
    p.trajectory.radii[k] = 0.04 + 0.06 * u01(*rng);
    p.trajectory.links[k] = k / 3;
  }
  p.trajectory.centres.resize(3, static_cast<Eigen::Index>(W) * S);
  p.trajectory.steps.resize(W);
  for (int w = 0; w < W; ++w) {
    p.trajectory.steps[w] = (w * T) / W;
    const double reach = 0.2 + 0.8 * w / std::max(1, W - 1);
    for (int k = 0; k < S; ++k) {
      p.trajectory.centres.col(static_cast<Eigen::Index>(w) * S + k) =
          Eigen::Vector3d(reach * (k + 1) / S, 0.1 * std::sin(w + k), 0.3 + 0.02 * k);
    }
  }
  return p;
}

// Brute force: every pair, every action, no pruning.
WaypointBound BruteForce(const Problem& p, int w) {
  WaypointBound best;
  best.bound = -1.0;
  const int S = p.trajectory.num_spheres();
  for (int k = 0; k < S; ++k) {
    for (int l = 0; l < p.prediction.num_spheres(); ++l) {
      int action = -1;
      const double v = EvaluateMixtureBound(
          p.prediction, p.trajectory.steps[w], l,
          p.trajectory.centres.col(static_cast<Eigen::Index>(w) * S + k),
          p.trajectory.radii[k], &action);
      if (v > best.bound) {
        best.bound = v;
        best.robot_sphere = k;
        best.human_sphere = l;
        best.action = action;
      }
    }
  }
  return best;
}

TEST(TrajectoryBoundTest, PrunedEqualsBruteForce) {
  std::mt19937_64 rng(99);
  long pruned = 0, evaluated = 0;
  int inexact = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Problem p = RandomProblem(&rng, 1 + trial % 5, 6, 8, 12, 10);
    TrajectoryBoundWorkspace ws(12, 8);
    std::vector<WaypointBound> out(10);
    TrajectoryBoundParams params;
    params.negligible = trial % 2 == 0 ? 1e-12 : 0.0;
    ASSERT_EQ(params.Validate(), "");
    EvaluateTrajectoryBound(p.prediction, p.trajectory, params, &ws, &out);
    for (int w = 0; w < 10; ++w) {
      const WaypointBound bf = BruteForce(p, w);
      const WaypointBound& r = out[w];
      pruned += r.pairs_pruned;
      evaluated += r.pairs_evaluated;
      EXPECT_EQ(r.pairs_pruned + r.pairs_evaluated, 12 * 8);
      // Always an upper bound of the brute-force maximum.
      EXPECT_GE(r.bound, bf.bound * (1 - 1e-12)) << trial << " " << w;
      if (r.exact) {
        EXPECT_NEAR(r.bound, bf.bound, 1e-12 * bf.bound) << trial << " " << w;
        // The reported pair attains the maximum.
        const double at_argmax = EvaluateMixtureBound(
            p.prediction, p.trajectory.steps[w], r.human_sphere,
            p.trajectory.centres.col(static_cast<Eigen::Index>(w) * 12 + r.robot_sphere),
            p.trajectory.radii[r.robot_sphere]);
        EXPECT_NEAR(at_argmax, bf.bound, 1e-12 * bf.bound);
        EXPECT_EQ(r.robot_link, p.trajectory.links[r.robot_sphere]);
        EXPECT_EQ(r.human_segment, p.prediction.segment(r.human_sphere));
      } else {
        ++inexact;
        EXPECT_LE(r.bound, params.negligible);
      }
    }
  }
  // The pruning must actually skip work on this workload.
  EXPECT_GT(pruned, evaluated);
}

TEST(TrajectoryBoundTest, FarAwayPersonGivesNegligibleInexactBound) {
  std::mt19937_64 rng(5);
  Problem p = RandomProblem(&rng, 3, 4, 4, 5, 4);
  // Move every robot sphere 20 m away.
  p.trajectory.centres.row(0).array() += 20.0;
  TrajectoryBoundWorkspace ws(5, 4);
  std::vector<WaypointBound> out(4);
  EvaluateTrajectoryBound(p.prediction, p.trajectory, {}, &ws, &out);
  for (int w = 0; w < 4; ++w) {
    const WaypointBound& r = out[w];
    EXPECT_EQ(r.pairs_evaluated, 0);
    EXPECT_FALSE(r.exact && r.bound > 0.0);
    EXPECT_LE(r.bound, 1e-12);
    EXPECT_GE(r.bound, BruteForce(p, w).bound);  // still an upper bound
    EXPECT_EQ(r.robot_sphere, -1);
  }
}

TEST(TrajectoryBoundTest, EvaluationDoesNotAllocate) {
  std::mt19937_64 rng(3);
  Problem p = RandomProblem(&rng, 10, 15, 16, 40, 30);
  TrajectoryBoundWorkspace ws(40, 16);
  std::vector<WaypointBound> out(30);
  test_support::StartCountingAllocations();
  EvaluateTrajectoryBound(p.prediction, p.trajectory, {}, &ws, &out);
  FactorizedGaussian g;
  FactorizeGaussian(Eigen::Vector3d::Zero(), RandomCovariance(&rng), &g);
  p.prediction.SetSphere(0, 0, 0, Eigen::Vector3d::Ones(), RandomCovariance(&rng));
  p.prediction.UpdateSummaries();
  EXPECT_EQ(test_support::StopCountingAllocations(), 0);
  // Sanity of the counter itself.
  test_support::StartCountingAllocations();
  auto* v = new std::vector<int>(10);
  const long counted = test_support::StopCountingAllocations();
  delete v;
  EXPECT_GT(counted, 0);
}

TEST(TrajectoryBoundDeathTest, StaleSummariesAbort) {
  std::mt19937_64 rng(8);
  Problem p = RandomProblem(&rng, 2, 3, 2, 3, 3);
  TrajectoryBoundWorkspace ws(3, 2);
  std::vector<WaypointBound> out(3);
  EXPECT_TRUE(p.prediction.summaries_up_to_date());
  // Moving a sphere without refreshing the summaries would make pruning unsound.
  p.prediction.SetSphere(0, 0, 0, Eigen::Vector3d(0.1, 0.0, 0.3), RandomCovariance(&rng));
  EXPECT_FALSE(p.prediction.summaries_up_to_date());
  EXPECT_DEATH(EvaluateTrajectoryBound(p.prediction, p.trajectory, {}, &ws, &out),
               "summaries_up_to_date");
  p.prediction.UpdateSummaries();
  EvaluateTrajectoryBound(p.prediction, p.trajectory, {}, &ws, &out);
  p.prediction.set_action_probability(1, 0.5);
  EXPECT_FALSE(p.prediction.summaries_up_to_date());
}

TEST(TrajectoryBoundTest, RejectsBadConstruction) {
  EXPECT_THROW(HumanPrediction(0, 1, {0.1}), std::invalid_argument);
  try {
    HumanPrediction(1, 1, {0.1, -0.2});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("radius of sphere 1 is -0.2"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(HumanPrediction(1, 1, {0.1, 0.2}, {1}), std::invalid_argument);
  HumanPrediction p(1, 1, {0.1});
  EXPECT_FALSE(p.SetSphere(0, 0, 0, Eigen::Vector3d::Zero(), -Eigen::Matrix3d::Identity()));
  TrajectoryBoundParams bad;
  bad.negligible = 2.0;
  EXPECT_NE(bad.Validate().find("negligible = 2"), std::string::npos);
}

}  // namespace
}  // namespace iplan::collision

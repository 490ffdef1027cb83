#include "iplan/intent/belief_filter.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace iplan::intent {
namespace {

Eigen::VectorXd P3(double a, double b, double c) { return Eigen::Vector3d(a, b, c); }

TEST(BeliefFilter, UniformBeforeFirstUpdateAndSumsToOne) {
  BeliefFilter f(3, {1.0, 1e-3});
  EXPECT_EQ(f.num_updates(), 0);
  EXPECT_NEAR(f.probabilities()(0), 1.0 / 3.0, 1e-12);
  f.Update(P3(0.2, 0.5, 0.3), 0.0);
  EXPECT_NEAR(f.probabilities().sum(), 1.0, 1e-12);
  // One window: the belief is that window's distribution.
  EXPECT_NEAR(f.probabilities()(1), 0.5, 1e-12);
}

TEST(BeliefFilter, ZeroTimeConstantIsTheLastWindow) {
  BeliefFilter f(3, {0.0, 1e-3});
  f.Update(P3(0.8, 0.1, 0.1), 0.0);
  f.Update(P3(0.1, 0.1, 0.8), 0.1);
  EXPECT_NEAR(f.probabilities()(2), 0.8, 1e-12);
  EXPECT_EQ(f.MostLikely(), 2);
}

TEST(BeliefFilter, ConsistentEvidenceOutvotesAFewStillWindows) {
  // Class 0 during the motion, then a few ambiguous windows slightly favouring
  // class 1 (the person stands still at the end): the last window alone picks
  // 1, the accumulated belief keeps 0.
  BeliefFilter f(3, {std::numeric_limits<double>::infinity(), 1e-3});
  double t = 0.0;
  for (int i = 0; i < 20; ++i, t += 0.1) f.Update(P3(0.6, 0.3, 0.1), t);
  for (int i = 0; i < 5; ++i, t += 0.1) f.Update(P3(0.3, 0.4, 0.3), t);
  EXPECT_EQ(f.MostLikely(), 0);
  EXPECT_GT(f.probabilities()(0), 0.5);
}

TEST(BeliefFilter, ForgettingLetsTheBeliefSwitchWhenTheActionChanges) {
  BeliefFilter forgetful(3, {0.5, 1e-3});
  BeliefFilter no_forgetting(3, {std::numeric_limits<double>::infinity(), 1e-3});
  double t = 0.0;
  for (int i = 0; i < 60; ++i, t += 0.1) {  // 6 s of action 0
    forgetful.Update(P3(0.7, 0.2, 0.1), t);
    no_forgetting.Update(P3(0.7, 0.2, 0.1), t);
  }
  EXPECT_EQ(forgetful.MostLikely(), 0);
  for (int i = 0; i < 20; ++i, t += 0.1) {  // then 2 s of action 2
    forgetful.Update(P3(0.1, 0.2, 0.7), t);
    no_forgetting.Update(P3(0.1, 0.2, 0.7), t);
  }
  EXPECT_EQ(forgetful.MostLikely(), 2);
  EXPECT_GT(forgetful.probabilities()(2), 0.6);
  EXPECT_EQ(no_forgetting.MostLikely(), 0);  // 60 old windows still outweigh 20 new ones
}

TEST(BeliefFilter, WeightsDependOnTimeNotOnTheUpdateRate) {
  // The same evidence at 15 Hz and at 30 Hz (each window twice) gives nearly
  // the same belief.
  BeliefFilter slow(2, {1.0, 1e-3}), fast(2, {1.0, 1e-3});
  for (int i = 0; i < 30; ++i) {
    const double t = i / 15.0;
    const Eigen::VectorXd p = Eigen::Vector2d(0.5 + 0.4 * std::sin(i), 0.5 - 0.4 * std::sin(i));
    slow.Update(p, t);
    fast.Update(p, t);
    fast.Update(p, t + 1.0 / 30.0);
  }
  EXPECT_NEAR(slow.probabilities()(0), fast.probabilities()(0), 0.05);
}

TEST(BeliefFilter, ProbabilityFloorBoundsAVeto) {
  BeliefFilter f(2, {std::numeric_limits<double>::infinity(), 1e-3});
  f.Update(Eigen::Vector2d(0.0, 1.0), 0.0);  // one window that rules class 0 out
  for (int i = 1; i <= 10; ++i) f.Update(Eigen::Vector2d(0.9, 0.1), 0.1 * i);
  EXPECT_EQ(f.MostLikely(), 0);
  EXPECT_TRUE(f.probabilities().allFinite());
}

TEST(BeliefFilter, ResetForgetsEverything) {
  BeliefFilter f(2, {std::numeric_limits<double>::infinity(), 1e-3});
  for (int i = 0; i < 10; ++i) f.Update(Eigen::Vector2d(0.9, 0.1), 0.1 * i);
  f.Reset();
  EXPECT_EQ(f.num_updates(), 0);
  EXPECT_NEAR(f.probabilities()(0), 0.5, 1e-12);
  f.Update(Eigen::Vector2d(0.2, 0.8), 0.0);  // stamps may restart after a reset
  EXPECT_NEAR(f.probabilities()(1), 0.8, 1e-12);
}

TEST(BeliefFilter, RejectsBadInput) {
  EXPECT_THROW(BeliefFilter(0), std::invalid_argument);
  EXPECT_THROW(BeliefFilter(2, {-1.0, 1e-3}), std::invalid_argument);
  EXPECT_THROW(BeliefFilter(2, {std::nan(""), 1e-3}), std::invalid_argument);
  EXPECT_THROW(BeliefFilter(2, {1.0, 0.0}), std::invalid_argument);
  BeliefFilter f(2, {1.0, 1e-3});
  EXPECT_THROW(f.Update(Eigen::Vector3d(0.3, 0.3, 0.4), 0.0), std::invalid_argument);
  EXPECT_THROW(f.Update(Eigen::Vector2d(std::nan(""), 0.5), 0.0), std::invalid_argument);
  f.Update(Eigen::Vector2d(0.5, 0.5), 1.0);
  EXPECT_THROW(f.Update(Eigen::Vector2d(0.5, 0.5), 0.5), std::invalid_argument);
}

}  // namespace
}  // namespace iplan::intent

// The bound against a person seen as points (point_bound.h): closed forms,
// monotone in the distance, and culling that never changes the bound.
#include "iplan/collision/point_bound.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace iplan::collision {
namespace {

constexpr double kPi = 3.14159265358979323846;

// One robot sphere of radius r at the given centres (one waypoint each).
RobotSpheresTrajectory OneSphere(const std::vector<Eigen::Vector3d>& centres, double r) {
  RobotSpheresTrajectory t;
  t.radii = {r};
  t.links = {3};
  t.centres.resize(3, static_cast<Eigen::Index>(centres.size()));
  for (std::size_t i = 0; i < centres.size(); ++i) {
    t.centres.col(static_cast<Eigen::Index>(i)) = centres[i];
    t.steps.push_back(static_cast<int>(i));
  }
  return t;
}

TEST(PointsBound, OneIsotropicPointMatchesTheClosedForm) {
  // Point at distance d from the sphere centre, Sigma = s I: x_max is on the
  // ball towards the mean, so the bound is V(R) (2 pi s)^-3/2 exp(-(d - R)^2 / 2s).
  const double s = 0.01 * 0.01, r_robot = 0.05, r_point = 0.005, R = r_robot + r_point;
  GaussianPoints pts;
  for (double d : {0.09, 0.1, 0.11}) {  // bounds 0.097, 1.8e-3, 8e-6
    Eigen::Matrix3Xd mu(3, 1);
    mu.col(0) = Eigen::Vector3d(d, 0, 0);
    ASSERT_EQ(pts.Set(mu, {s * Eigen::Matrix3d::Identity()}, r_point), std::nullopt);
    std::vector<WaypointBound> out;
    EvaluatePointsBound(pts, OneSphere({Eigen::Vector3d::Zero()}, r_robot), PointsBoundParams{}, &out);
    ASSERT_EQ(out.size(), 1u);
    const double expected = 4.0 / 3.0 * kPi * R * R * R * std::pow(2 * kPi * s, -1.5) *
                            std::exp(-(d - R) * (d - R) / (2 * s));
    EXPECT_NEAR(out[0].bound, std::min(1.0, expected), 1e-9 * std::max(expected, 1e-9)) << "d " << d;
    EXPECT_EQ(out[0].robot_link, 3);
    EXPECT_EQ(out[0].human_sphere, 0);
  }
}

TEST(PointsBound, GrowsAsAPatchOfPointsApproaches) {
  // A 10 x 10 patch of points (2 cm grid, sigma 1 cm) facing the sphere.
  const double r_robot = 0.08;
  double previous = -1;
  for (double gap : {0.08, 0.06, 0.05, 0.04, 0.03}) {
    Eigen::Matrix3Xd mu(3, 100);
    for (int i = 0; i < 100; ++i) mu.col(i) = Eigen::Vector3d(r_robot + gap, 0.02 * (i % 10 - 4.5), 0.02 * (i / 10 - 4.5));
    GaussianPoints pts;
    ASSERT_EQ(pts.Set(mu, std::vector<Eigen::Matrix3d>(100, 1e-4 * Eigen::Matrix3d::Identity()), 0.005), std::nullopt);
    std::vector<WaypointBound> out;
    EvaluatePointsBound(pts, OneSphere({Eigen::Vector3d::Zero()}, r_robot), PointsBoundParams{}, &out);
    SCOPED_TRACE("gap " + std::to_string(gap));
    EXPECT_GT(out[0].bound, previous);
    previous = out[0].bound;
  }
  EXPECT_GT(previous, 0.05);  // 3 cm surface gap at 1 cm noise: no longer negligible
}

TEST(PointsBound, CullingNeverChangesTheBound) {
  // Seeded random clouds around a sphere sweeping past: culled and all-pairs
  // maxima are equal wherever the latter exceeds `negligible`; elsewhere the
  // culled result is `negligible`, still above the all-pairs maximum.
  std::mt19937 rng(18);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u(-0.4, 0.4), log_sigma(std::log(0.003), std::log(0.03));
  int compared = 0, culled_waypoints = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 400;
    Eigen::Matrix3Xd mu(3, n);
    std::vector<Eigen::Matrix3d> cov(n);
    for (int i = 0; i < n; ++i) {
      mu.col(i) = Eigen::Vector3d(u(rng), u(rng), u(rng));
      Eigen::Matrix3d a;
      for (int e = 0; e < 9; ++e) a(e / 3, e % 3) = n01(rng);
      const double sg = std::exp(log_sigma(rng));
      cov[static_cast<std::size_t>(i)] = sg * sg * (0.2 * Eigen::Matrix3d::Identity() + a * a.transpose() / 3.0);
    }
    GaussianPoints pts;
    ASSERT_EQ(pts.Set(mu, cov, 0.005, 0.05 + 0.01 * trial), std::nullopt);
    std::vector<Eigen::Vector3d> path;
    for (int w = 0; w < 15; ++w) path.emplace_back(-0.5 + w / 14.0, 0.1 * std::sin(trial), 0.0);
    const RobotSpheresTrajectory t = OneSphere(path, 0.06);
    std::vector<WaypointBound> fast, all;
    EvaluatePointsBound(pts, t, PointsBoundParams{}, &fast);
    EvaluatePointsBoundAllPairs(pts, t, &all);
    for (int w = 0; w < 15; ++w) {
      if (all[w].bound >= 1e-9) {
        EXPECT_EQ(fast[w].bound, all[w].bound) << "trial " << trial << " waypoint " << w;
        EXPECT_EQ(fast[w].human_sphere, all[w].human_sphere);
        ++compared;
      } else {
        EXPECT_GE(fast[w].bound, all[w].bound);
        EXPECT_LE(fast[w].bound, 1e-9);
      }
      EXPECT_LT(fast[w].pairs_evaluated, all[w].pairs_evaluated);
      culled_waypoints += fast[w].pairs_pruned > 0;
    }
  }
  EXPECT_GT(compared, 30);        // the comparison is not vacuous
  EXPECT_EQ(culled_waypoints, 300);  // and culling did cull
}

TEST(PointsBound, BadPointsAreRefused) {
  GaussianPoints pts;
  Eigen::Matrix3Xd mu = Eigen::Matrix3Xd::Zero(3, 2);
  std::vector<Eigen::Matrix3d> cov(2, 1e-4 * Eigen::Matrix3d::Identity());
  cov[1](2, 2) = -1e-4;
  const auto why = pts.Set(mu, cov, 0.005);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("point 1"), std::string::npos) << *why;
  EXPECT_TRUE(pts.empty());
  EXPECT_NE(pts.Set(mu, {cov[0]}, 0.005), std::nullopt);
  EXPECT_NE(pts.Set(mu, {cov[0], cov[0]}, -1.0), std::nullopt);
  mu(0, 0) = std::nan("");
  EXPECT_NE(pts.Set(mu, {cov[0], cov[0]}, 0.005), std::nullopt);
}

}  // namespace
}  // namespace iplan::collision

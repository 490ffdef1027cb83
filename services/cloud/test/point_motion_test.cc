// The human points' velocities (core/point_motion.h): parts of synthetic,
// seeded point clusters seen from one side as a depth camera sees them. A
// moving cluster's parts converge on its velocity while their uncertainty
// shrinks; a hand reaching out of a still body moves, the body does not; a
// still cluster whose visible half changes does not gain a large speed; a
// region coming into view next to a tracked body is tracked at once; a gap
// starts afresh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

#include "services/cloud/core/point_motion.h"

namespace iplan::cloud_service {
namespace {

constexpr int64_t kFrameNs = 100'000'000;  // 10 Hz, the cell's camera rate
constexpr int64_t kStartNs = 1'000'000'000'000;

// Points on the half of a sphere facing the camera (towards +y), about
// 3 cm apart (the cloud stage's voxel grid), with 2 mm noise.
std::vector<Eigen::Vector3d> Blob(const Eigen::Vector3d& centre, double radius, std::mt19937* rng,
                                  double min_x = -1e9) {
  std::normal_distribution<double> noise(0.0, 0.002);
  const int n = std::max(8, static_cast<int>(4 * M_PI * radius * radius / (0.03 * 0.03)));
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < n; ++i) {  // Fibonacci sphere
    const double z = 1 - 2 * (i + 0.5) / n, r = std::sqrt(1 - z * z), phi = i * M_PI * (3 - std::sqrt(5.0));
    const Eigen::Vector3d u(r * std::cos(phi), r * std::sin(phi), z);
    if (u.y() < 0 || u.x() * radius < min_x) continue;
    out.push_back(centre + radius * u + Eigen::Vector3d(noise(*rng), noise(*rng), noise(*rng)));
  }
  return out;
}

double MaxStd(const MotionPart& p) {
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(p.velocity_covariance()).eigenvalues().maxCoeff());
}

TEST(PointMotion, MovingClusterConvergesAndItsUncertaintyShrinks) {
  MotionTracker tracker{MotionParams{}};
  std::mt19937 rng(7);
  const Eigen::Vector3d v(0.4, -0.3, 0.1), start(1.2, 0.0, 0.9);
  std::vector<double> worst_std;
  std::vector<int> part_of;
  std::vector<Eigen::Vector3d> pts;
  for (int f = 0; f < 20; ++f) {
    pts = Blob(start + v * (f * 0.1), 0.18, &rng);
    part_of = tracker.Update(pts, kStartNs + f * kFrameNs);
    double worst = 0;
    for (const MotionPart& p : tracker.parts()) worst = std::max(worst, MaxStd(p));
    worst_std.push_back(worst);
  }
  // Uncertainty: large at first, shrinking, small at the end.
  EXPECT_GE(worst_std[0], 0.99);
  EXPECT_LT(worst_std[5], 0.5 * worst_std[0]);
  EXPECT_LT(worst_std.back(), worst_std[2]);
  EXPECT_LT(worst_std.back(), MotionParams{}.tracked_speed_sigma);
  // Every point in a tracked part whose velocity is the cluster's.
  for (std::size_t i = 0; i < pts.size(); ++i) {
    ASSERT_GE(part_of[i], 0);
    const MotionPart& p = tracker.parts()[static_cast<std::size_t>(part_of[i])];
    EXPECT_TRUE(tracker.Tracked(p));
    EXPECT_LT((p.velocity() - v).norm(), 0.1) << "part " << p.id << " velocity " << p.velocity().transpose();
  }
  std::cout << "moving cluster: " << tracker.parts().size() << " parts; largest velocity std at frames 1, 3, 6, 20: "
            << worst_std[0] << " " << worst_std[2] << " " << worst_std[5] << " " << worst_std.back() << " m/s\n";
}

TEST(PointMotion, AStillClusterIsTrackedAtRestWithinAFewFrames) {
  MotionTracker tracker{MotionParams{}};
  std::mt19937 rng(8);
  int first_tracked = -1;
  std::vector<int> part_of;
  for (int f = 0; f < 15; ++f) {
    part_of = tracker.Update(Blob({1.3, 0.0, 1.0}, 0.2, &rng), kStartNs + f * kFrameNs);
    bool all = true;
    for (int k : part_of) all = all && k >= 0 && tracker.Tracked(tracker.parts()[static_cast<std::size_t>(k)]);
    if (all && first_tracked < 0) first_tracked = f;
  }
  EXPECT_GE(first_tracked, 1);  // never at the first sight
  EXPECT_LE(first_tracked, 4);
  for (const MotionPart& p : tracker.parts()) EXPECT_LT(p.velocity().norm(), 0.1) << p.velocity().transpose();
}

// A person at the table reaching towards the robot: the body stays, the hand
// reaches 0.5 m in 0.8 s (minimum jerk, 1.17 m/s at its peak). At the
// peak, the hand's points carry its speed (with collision risk's 2 sigma,
// at least 90 % of the true speed) or no speed at all (then the monitor
// takes the ISO default), the body's do not: a single centroid for the
// cluster would give the hand about a tenth of its speed.
TEST(PointMotion, AHandReachingOutOfAStillBodyMovesTheBodyDoesNot) {
  MotionTracker tracker{MotionParams{}};
  std::mt19937 rng(9);
  const Eigen::Vector3d body(1.3, 0.0, 1.0), hand0(0.9, 0.0, 1.0);
  constexpr double kDistance = 0.5, kDuration = 0.8;
  auto hand_x = [&](double t) {  // minimum jerk
    const double s = std::clamp(t / kDuration, 0.0, 1.0);
    return hand0.x() - kDistance * (10 * std::pow(s, 3) - 15 * std::pow(s, 4) + 6 * std::pow(s, 5));
  };
  std::vector<int> part_of;
  std::size_t n_body = 0;
  double hand_v_h = 1e9, body_speed = 0;
  int hand_untracked = 0, body_untracked = 0;
  for (int f = 0; f <= 10; ++f) {
    const double t = (f - 6) * 0.1;  // the reach starts at frame 6, peaks at frame 10
    std::vector<Eigen::Vector3d> pts = Blob(body, 0.2, &rng);
    n_body = pts.size();
    for (const Eigen::Vector3d& p : Blob({hand_x(t), hand0.y(), hand0.z()}, 0.05, &rng)) pts.push_back(p);
    part_of = tracker.Update(pts, kStartNs + f * kFrameNs);
  }
  for (std::size_t i = 0; i < part_of.size(); ++i) {
    const bool tracked = part_of[i] >= 0 && tracker.Tracked(tracker.parts()[static_cast<std::size_t>(part_of[i])]);
    if (i < n_body) {
      body_untracked += !tracked;
      if (tracked) body_speed = std::max(body_speed, tracker.parts()[static_cast<std::size_t>(part_of[i])].velocity().norm());
    } else if (!tracked) {
      ++hand_untracked;
    } else {
      const MotionPart& p = tracker.parts()[static_cast<std::size_t>(part_of[i])];
      hand_v_h = std::min(hand_v_h, -p.velocity().x() + 2 * std::sqrt(p.velocity_covariance()(0, 0)));
    }
  }
  const double peak = 1.875 * kDistance / kDuration;
  std::cout << "at the reach's peak (" << peak << " m/s): hand points' v_h (2 sigma) >= " << hand_v_h << " m/s, "
            << hand_untracked << " not tracked; body points' speed <= " << body_speed << " m/s, " << body_untracked << " of "
            << n_body << " not tracked\n";
  EXPECT_GE(hand_v_h, 0.9 * peak);
  // Untracked points are judged at the ISO default (safe), but a hand never tracked would prove nothing here.
  EXPECT_LE(hand_untracked, static_cast<int>(part_of.size() - n_body) / 2);
  EXPECT_LT(body_speed, 0.15);
  EXPECT_LE(body_untracked, static_cast<int>(n_body) / 10);
}

// The visible share of a still cluster changes (the right half hidden for a
// while, then seen again): its parts' centroids jump by centimetres. The
// guards (visibility_sigma, gate) keep the speed this gives small; without
// them it is larger.
TEST(PointMotion, AChangeOfTheVisiblePartGivesNoLargeSpeed) {
  auto worst_speed = [](bool guarded) {
    MotionParams params;
    if (!guarded) {
      params.gate = 1e12;
      params.visibility_sigma = 0;
    }
    MotionTracker tracker(params);
    std::mt19937 rng(10);
    double worst = 0;
    for (int f = 0; f < 30; ++f) {
      const bool hidden = f >= 10 && f < 20;
      tracker.Update(Blob({1.3, 0.0, 1.0}, 0.25, &rng, hidden ? -0.05 : -1e9), kStartNs + f * kFrameNs);
      for (const MotionPart& p : tracker.parts()) {
        if (f >= 5 && tracker.Tracked(p)) worst = std::max(worst, p.velocity().norm());
      }
    }
    return worst;
  };
  const double guarded = worst_speed(true), plain = worst_speed(false);
  std::cout << "visible half changes: largest tracked speed " << guarded << " m/s guarded, " << plain
            << " m/s without the guards\n";
  EXPECT_LT(guarded, 0.35);
  EXPECT_LT(guarded, 0.7 * plain);
}

TEST(PointMotion, AGapStartsAfreshAndNewPartsAreNotTracked) {
  MotionTracker tracker{MotionParams{}};
  std::mt19937 rng(11);
  for (int f = 0; f < 6; ++f) tracker.Update(Blob({1.3, 0.0, 1.0}, 0.15, &rng), kStartNs + f * kFrameNs);
  ASSERT_FALSE(tracker.parts().empty());
  const uint32_t old_max = tracker.parts().back().id;
  const std::vector<int> part_of = tracker.Update(Blob({1.3, 0.0, 1.0}, 0.15, &rng), kStartNs + 6 * kFrameNs + 600'000'000);
  for (int k : part_of) {
    ASSERT_GE(k, 0);
    EXPECT_GT(tracker.parts()[static_cast<std::size_t>(k)].id, old_max);
    EXPECT_FALSE(tracker.Tracked(tracker.parts()[static_cast<std::size_t>(k)]));
  }
  // Nobody left: the parts are lost after lost_frames.
  for (int f = 0; f <= MotionParams{}.lost_frames; ++f) tracker.Update({}, kStartNs + (8 + f) * kFrameNs);
  EXPECT_TRUE(tracker.parts().empty());
}

// A region of a still body that comes into view (from behind the robot's
// arm) next to its tracked parts is tracked from its first frame, at their
// velocity, with the relative motion allowed as its uncertainty; a blob far
// from every part is not (the ISO speed until its own filter converges).
TEST(PointMotion, ARegionComingIntoViewNextToATrackedBodyIsTrackedAtOnce) {
  const MotionParams params;
  MotionTracker tracker{params};
  std::mt19937 rng(12);
  const Eigen::Vector3d body(1.3, 0.0, 1.0);
  // Followed for a few frames: tracked, some parts' velocity std still
  // high enough that a part seeded from them is beyond tracked_speed_sigma.
  constexpr int kFrames = 3;
  for (int f = 0; f < kFrames; ++f) tracker.Update(Blob(body, 0.15, &rng), kStartNs + f * kFrameNs);
  for (const MotionPart& p : tracker.parts()) ASSERT_TRUE(tracker.Tracked(p));
  std::vector<Eigen::Vector3d> pts = Blob(body, 0.15, &rng);
  const std::size_t body_points = pts.size();
  // A forearm below the body (beyond the reach of its parts' balls, within two
  // part radii of their centres), and a blob 1 m away.
  for (const Eigen::Vector3d& q : Blob(body + Eigen::Vector3d(0.0, 0.0, -0.45), 0.05, &rng)) pts.push_back(q);
  const std::size_t near_end = pts.size();
  for (const Eigen::Vector3d& q : Blob(body + Eigen::Vector3d(0.0, -1.0, 0.0), 0.06, &rng)) pts.push_back(q);
  const std::vector<int> part_of = tracker.Update(pts, kStartNs + kFrames * kFrameNs);
  int near_new = 0, far_tracked = 0;
  for (std::size_t i = body_points; i < pts.size(); ++i) {
    ASSERT_GE(part_of[i], 0);
    const MotionPart& p = tracker.parts()[static_cast<std::size_t>(part_of[i])];
    if (i < near_end) {
      if (!p.from_neighbour) continue;  // joined a body part
      ++near_new;
      EXPECT_TRUE(tracker.Tracked(p));
      EXPECT_LT(p.velocity().norm(), 0.1);
      // Beyond the limit of a part's own filter: trusted through its neighbour.
      EXPECT_GT(MaxStd(p), params.tracked_speed_sigma);
      EXPECT_LE(MaxStd(p), std::hypot(params.tracked_speed_sigma, params.neighbour_speed_sigma));
    } else {
      EXPECT_FALSE(p.from_neighbour);
      far_tracked += tracker.Tracked(p);
    }
  }
  EXPECT_GT(near_new, 0) << "the forearm joined the body's parts: the test shows nothing";
  EXPECT_EQ(far_tracked, 0);
}

// A part of a tracked body whose own filter loses track (only 3 of its
// points seen, fewer than min_points, for three frames: its velocity
// variance grows past the limit) is judged at its tracked neighbour's
// velocity with the relative motion allowed, as a part seeded there is, not
// at the ISO speed; a blob with nothing tracked near it still is.
TEST(PointMotion, APartThatLosesTrackNextToATrackedBodyIsJudgedAtItsNeighboursVelocity) {
  const MotionParams params;
  MotionTracker tracker{params};
  std::mt19937 rng(13);
  // The forearm beside the body: beyond the reach of the body part's ball, within two part radii of its centre.
  const Eigen::Vector3d body(1.3, 0.0, 1.0), forearm = body + Eigen::Vector3d(0.37, 0.05, 0.0);
  int64_t t = kStartNs;
  for (int f = 0; f < 6; ++f, t += kFrameNs) {
    std::vector<Eigen::Vector3d> pts = Blob(body, 0.15, &rng);
    for (const Eigen::Vector3d& q : Blob(forearm, 0.05, &rng)) pts.push_back(q);
    tracker.Update(pts, t);
  }
  std::vector<Eigen::Vector3d> pts;
  std::vector<int> part_of;
  for (int f = 0; f < params.lost_frames; ++f, t += kFrameNs) {
    pts = Blob(body, 0.15, &rng);
    const std::size_t body_points = pts.size();
    const std::vector<Eigen::Vector3d> arm = Blob(forearm, 0.05, &rng);
    pts.insert(pts.end(), arm.begin(), arm.begin() + 3);
    pts.push_back(body + Eigen::Vector3d(0.0, -1.0, 0.0));  // far from everything
    part_of = tracker.Update(pts, t);
    ASSERT_EQ(part_of.size(), body_points + 4);
  }
  int judged_by_neighbour = 0;
  for (std::size_t i = pts.size() - 4; i + 1 < pts.size(); ++i) {
    ASSERT_GE(part_of[i], 0);
    const std::size_t k = static_cast<std::size_t>(part_of[i]);
    const MotionPart& p = tracker.parts()[k];
    const std::optional<PartVelocity> v = tracker.VelocityOf(k);
    ASSERT_TRUE(v.has_value()) << "a forearm point next to the tracked body is left to the ISO speed";
    if (tracker.Tracked(p)) continue;
    ++judged_by_neighbour;
    EXPECT_GT(p.unseen, 0);
    EXPECT_LT(v->velocity.norm(), 0.1);
    const double extra = params.neighbour_speed_sigma * params.neighbour_speed_sigma;
    EXPECT_GE(v->covariance.diagonal().minCoeff(), extra);
    // The neighbour's own variance, no more: below the part's grown own one.
    EXPECT_LT(v->covariance.trace() - 3 * extra, p.velocity_covariance().trace());
  }
  EXPECT_GT(judged_by_neighbour, 0) << "the forearm's part stayed tracked: the test shows nothing";
  const std::size_t far = static_cast<std::size_t>(part_of.back());
  EXPECT_FALSE(tracker.VelocityOf(far).has_value());
}

TEST(PointMotion, ParametersAreChecked) {
  MotionParams p;
  p.part_radius = 0;
  EXPECT_EQ(p.Validate(), "part_radius must be > 0 m");
  p = MotionParams{};
  p.min_points = 0;
  EXPECT_EQ(p.Validate(), "min_points must be >= 1, got 0");
  p = MotionParams{};
  p.gate = -1;
  EXPECT_THROW(MotionTracker{p}, std::invalid_argument);
}

}  // namespace
}  // namespace iplan::cloud_service

#include "../core/synthetic_person.h"

#include <gtest/gtest.h>

namespace iplan::perception {
namespace {

TEST(SyntheticPerson, ArmSegmentsKeepTheirLengthAndHandReachesTarget) {
  SyntheticPersonParams p;
  p.noise_stddev = 0;
  SyntheticPerson person(p);
  double closest = 1e9;
  for (double t = 0; t < p.reach_period; t += 0.01) {
    const auto pose = person.TruePose(t);
    ASSERT_EQ(pose.size(), 9u);
    const Eigen::Vector3d shoulder = pose[6].position_W, elbow = pose[7].position_W, hand = pose[8].position_W;
    EXPECT_NEAR((elbow - shoulder).norm(), 0.30, 1e-6) << "t=" << t;
    EXPECT_NEAR((hand - elbow).norm(), 0.28, 1e-6) << "t=" << t;
    closest = std::min(closest, (hand - p.reach_target_W).norm());
  }
  EXPECT_LT(closest, 1e-6);  // the default target is within reach
}

TEST(SyntheticPerson, NoiseIsSeededAndHasTheConfiguredSpread) {
  SyntheticPersonParams p;
  p.noise_stddev = 0.02;
  SyntheticPerson a(p), b(p);
  double sum2 = 0;
  int n = 0;
  for (int k = 0; k < 2000; ++k) {
    const auto oa = a.Observe(0.5), ob = b.Observe(0.5), truth = a.TruePose(0.5);
    EXPECT_EQ(oa[8].position_W, ob[8].position_W);
    sum2 += (oa[8].position_W - truth[8].position_W).squaredNorm();
    n += 3;
  }
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.02, 0.001);
}

TEST(SyntheticPerson, ValidateRejectsBadParams) {
  SyntheticPersonParams p;
  p.reach_period = 0;
  EXPECT_EQ(p.Validate(), "reach_period must be > 0");
}

}  // namespace
}  // namespace iplan::perception

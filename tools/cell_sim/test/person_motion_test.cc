// The scenario people: a hand sweep (the shared-space suite's crossing)
// takes the synthetic person's hand from its own motion along the line and
// back, keeps the arm a two-link arm within reach, and changes nothing
// outside its time.
#include "tools/cell_sim/core/person_motion.h"

#include <algorithm>

#include <gtest/gtest.h>

namespace iplan::cell_sim {
namespace {

constexpr double kRate = 30;

class HandSweepTest : public ::testing::Test {
 protected:
  HandSweepTest() {
    person_.torso_W = {1.2, 0.0, 0.25};
    person_.facing_yaw = 3.14159265358979;
    person_.actions = {perception::ActionMotion{"idle", perception::MotionKind::kRest, true, {0, 0, 0}, 3.0, 0.02}};
    joints_ = perception::UpperBodyJointNames();
    sweep_.right_hand = true;
    sweep_.from_W = {0.75, 0.30, 0.30};
    sweep_.to_W = {0.75, -0.05, 0.30};
    sweep_.start = 1.0;
    sweep_.approach = 0.6;
    sweep_.duration = 1.2;
  }
  int Joint(const std::string& name) const {
    return static_cast<int>(std::find(joints_.begin(), joints_.end(), name) - joints_.begin());
  }
  PersonStream Stream(const std::optional<HandSweep>& sweep) const {
    SyntheticPlacement place;
    place.sweep = sweep;
    return SyntheticPersonStream(person_, place, joints_, kRate, 5.0, 0.0, 1);
  }

  perception::SyntheticPersonParams person_;
  std::vector<std::string> joints_;
  HandSweep sweep_;
};

TEST_F(HandSweepTest, TheHandTravelsTheLineAndComesBack) {
  const PersonStream plain = Stream(std::nullopt), swept = Stream(sweep_);
  ASSERT_EQ(plain.num_frames(), swept.num_frames());
  const int hand = Joint("hand_r"), elbow = Joint("elbow_r"), shoulder = Joint("shoulder_r");
  const auto frame = [](double t) { return static_cast<std::size_t>(std::lround(t * kRate)); };
  // At the ends of the line and halfway along it (all within reach here).
  const double t_from = sweep_.start + sweep_.approach, t_to = t_from + sweep_.duration;
  EXPECT_LT((swept.truth[frame(t_from)].col(hand) - sweep_.from_W).norm(), 1e-9);
  EXPECT_LT((swept.truth[frame(t_to)].col(hand) - sweep_.to_W).norm(), 1e-9);
  EXPECT_NEAR(sweep_.middle(), t_from + 0.6, 1e-12);
  EXPECT_LT((swept.truth[frame(sweep_.middle())].col(hand) - 0.5 * (sweep_.from_W + sweep_.to_W)).norm(), 1e-9);
  // The arm stays a 0.30 m upper arm and a 0.28 m forearm throughout.
  for (std::size_t i = frame(sweep_.start); i <= frame(t_to + sweep_.approach); ++i) {
    const Eigen::Matrix3Xd& p = swept.truth[i];
    EXPECT_NEAR((p.col(elbow) - p.col(shoulder)).norm(), 0.30, 1e-6) << "frame " << i;
    EXPECT_NEAR((p.col(hand) - p.col(elbow)).norm(), 0.28, 1e-6) << "frame " << i;
  }
  // Outside the sweep, and the other joints always, as without it.
  for (std::size_t i = 0; i < plain.truth.size(); ++i) {
    const double t = plain.stamp(static_cast<int>(i));
    for (int j = 0; j < static_cast<int>(joints_.size()); ++j) {
      const bool moved = (j == hand || j == elbow) && t >= sweep_.start && t <= t_to + sweep_.approach;
      if (!moved) {
        EXPECT_EQ(swept.truth[i].col(j), plain.truth[i].col(j)) << joints_[j] << " at " << t;
      }
    }
  }
}

TEST_F(HandSweepTest, AnOutOfReachLineIsFollowedAtArmsLength) {
  sweep_.from_W = {0.2, 0.5, 0.3};  // about 1 m from the right shoulder
  sweep_.to_W = {0.2, -0.5, 0.3};
  const PersonStream swept = Stream(sweep_);
  const int hand = Joint("hand_r"), shoulder = Joint("shoulder_r");
  const Eigen::Matrix3Xd& p = swept.truth[static_cast<std::size_t>(std::lround(sweep_.middle() * kRate))];
  EXPECT_NEAR((p.col(hand) - p.col(shoulder)).norm(), 0.97 * 0.58, 1e-9);
}

TEST_F(HandSweepTest, BadSweepsAreRefused) {
  sweep_.duration = 0;
  try {
    Stream(sweep_);
    ADD_FAILURE() << "a sweep of 0 s was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("duration must be > 0"), std::string::npos) << e.what();
  }
  sweep_.duration = 1.0;
  SyntheticPlacement place;
  place.sweep = sweep_;
  try {
    SyntheticPersonStream(person_, place, {"head", "hand_r"}, kRate, 2.0, 0.0, 1);
    ADD_FAILURE() << "a body without elbow_r was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'elbow_r'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace iplan::cell_sim

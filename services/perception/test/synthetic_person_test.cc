#include "../core/synthetic_person.h"

#include <algorithm>
#include <map>

#include <gtest/gtest.h>

namespace iplan::perception {
namespace {

// The demo cell's person: reach into the parts bin, assemble, idle.
SyntheticPersonParams CellPerson() {
  SyntheticPersonParams p;
  p.torso_W = {1.05, 0.0, 0.35};
  p.noise_stddev = 0;
  p.actions = {{"reach_parts", MotionKind::kReach, true, {0.62, 0.38, 0.22}, 2.0, 0.0},
               {"assemble", MotionKind::kWork, true, {0.72, 0.0, 0.15}, 1.2, 0.04},
               {"idle", MotionKind::kRest, true, {0, 0, 0}, 3.0, 0.02}};
  p.script = {{"reach_parts", 4.0}, {"assemble", 6.0}, {"idle", 2.0}};
  p.loop = false;
  p.variation = 0.03;
  return p;
}

TEST(SyntheticPerson, ArmSegmentsKeepTheirLengthAndHandReachesTarget) {
  SyntheticPersonParams p;
  p.noise_stddev = 0;
  SyntheticPerson person(p);
  double closest = 1e9;
  for (double t = 0; t < p.actions[0].period; t += 0.01) {
    const auto pose = person.TruePose(t);
    ASSERT_EQ(pose.size(), 9u);
    const Eigen::Vector3d shoulder = pose[6].position_W, elbow = pose[7].position_W, hand = pose[8].position_W;
    EXPECT_NEAR((elbow - shoulder).norm(), 0.30, 1e-6) << "t=" << t;
    EXPECT_NEAR((hand - elbow).norm(), 0.28, 1e-6) << "t=" << t;
    closest = std::min(closest, (hand - p.actions[0].target_W).norm());
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
  p.actions[0].period = 0;
  EXPECT_EQ(p.Validate(), "action 'reach': period must be > 0");
  p = CellPerson();
  p.script.push_back({"dance", 1.0});
  EXPECT_EQ(p.Validate(), "script step 'dance' names no defined action");
  p = CellPerson();
  p.actions.push_back(p.actions[0]);
  EXPECT_EQ(p.Validate(), "action 'reach_parts' is defined twice");
  EXPECT_THROW(SyntheticPerson{p}, std::invalid_argument);
}

TEST(SyntheticPerson, FollowsTheScriptFromEachStartAndHoldsTheLastAction) {
  SyntheticPerson person(CellPerson());
  EXPECT_EQ(person.ActionAt(0.0), "idle");  // waiting for the first start
  EXPECT_EQ(person.ActionAt(50.0), "idle");
  person.StartScript(10.0);
  EXPECT_EQ(person.episode(), 1);
  EXPECT_EQ(person.ActionAt(9.9), "idle");
  EXPECT_EQ(person.ActionAt(10.1), "reach_parts");
  EXPECT_EQ(person.ActionAt(13.9), "reach_parts");
  EXPECT_EQ(person.ActionAt(14.1), "assemble");
  EXPECT_EQ(person.ActionAt(19.9), "assemble");
  EXPECT_EQ(person.ActionAt(20.1), "idle");
  EXPECT_EQ(person.ActionAt(100.0), "idle");  // no loop: holds the last action
  person.StartScript(100.0);
  EXPECT_EQ(person.ActionAt(100.5), "reach_parts");

  SyntheticPersonParams looping = CellPerson();
  looping.loop = true;
  SyntheticPerson l(looping);
  EXPECT_EQ(l.ActionAt(0.5), "reach_parts");  // starts by itself
  EXPECT_EQ(l.ActionAt(12.5), "reach_parts");  // second cycle of the 12 s script
  EXPECT_EQ(l.ActionAt(17.0), "assemble");
}

TEST(SyntheticPerson, HandsMoveWithTheActionAndContinuouslyAcrossSteps) {
  SyntheticPersonParams p = CellPerson();
  SyntheticPerson person(p);
  person.StartScript(0.0);
  double closest_to_bin = 1e9, max_step = 0, hand_spread_assembling = 0;
  Eigen::Vector3d last = person.TruePose(0)[8].position_W;
  for (double t = 0.0; t < 12.0; t += 1.0 / 300) {
    const auto pose = person.TruePose(t);
    const Eigen::Vector3d hand_r = pose[8].position_W, hand_l = pose[5].position_W;
    if (t < 4.0) closest_to_bin = std::min(closest_to_bin, (hand_r - p.actions[0].target_W).norm());
    if (t > 5.0 && t < 10.0) {
      // Both hands work near the assembly point.
      EXPECT_LT((0.5 * (hand_l + hand_r) - p.actions[1].target_W).norm(), 0.15) << "t=" << t;
      hand_spread_assembling = std::max(hand_spread_assembling, (hand_l - hand_r).norm());
    }
    max_step = std::max(max_step, (hand_r - last).norm());
    last = hand_r;
  }
  EXPECT_LT(closest_to_bin, 0.12);  // within the variation of the bin
  EXPECT_GT(hand_spread_assembling, 0.15);
  EXPECT_LT(max_step, 0.02);  // < 6 m/s at 300 Hz: no jumps, also at step changes
}

TEST(SyntheticPerson, RepetitionsVaryButArePerfectlyRepeatableForASeed) {
  SyntheticPersonParams p = CellPerson();
  SyntheticPerson a(p), b(p);
  a.StartScript(0.0);
  b.StartScript(0.0);
  // The hand is at its target 0.9 s into each 2 s reach.
  const Eigen::Vector3d first = a.TruePose(0.9)[8].position_W, second = a.TruePose(2.9)[8].position_W;
  EXPECT_GT((first - second).norm(), 1e-3);
  EXPECT_LT((first - p.actions[0].target_W).norm(), 0.15);
  EXPECT_EQ(first, b.TruePose(0.9)[8].position_W);
  p.variation = 0;
  SyntheticPerson c(p);
  c.StartScript(0.0);
  EXPECT_LT((c.TruePose(0.9)[8].position_W - c.TruePose(2.9)[8].position_W).norm(), 1e-9);
}

TEST(SyntheticPerson, DemonstrationsCoverEveryActionPerSubject) {
  SyntheticPersonParams p = CellPerson();
  p.noise_stddev = 0.01;
  const intent::SkeletonDataset d = RecordDemonstrations(p, 3, 2, 2.0, 15.0);
  ASSERT_EQ(d.sequences.size(), 3u * 3u * 2u);
  EXPECT_EQ(d.joint_names, UpperBodyJointNames());
  std::map<std::string, int> per_action;
  for (const auto& s : d.sequences) {
    ++per_action[s.action];
    EXPECT_EQ(s.time.size(), 30);
    EXPECT_EQ(s.positions.rows(), 30);
    EXPECT_EQ(s.positions.cols(), 27);
    EXPECT_TRUE(s.positions.allFinite());
  }
  EXPECT_EQ(per_action["reach_parts"], 6);
  EXPECT_EQ(per_action["assemble"], 6);
  const intent::SkeletonDataset again = RecordDemonstrations(p, 3, 2, 2.0, 15.0);
  EXPECT_EQ(again.sequences[5].positions, d.sequences[5].positions);
  EXPECT_THROW(RecordDemonstrations(p, 0, 2, 2.0, 15.0), std::invalid_argument);
}

TEST(SyntheticPerson, ReachingIsTheReachingHandWhileItMovesToTheTargetOrBack) {
  SyntheticPerson person(CellPerson());
  person.StartScript(0.0);
  // reach_parts: period 2 s, out 0-0.8 s, hold, back 1.0-1.8 s, hold; the right hand (index 8).
  for (double t : {0.1, 0.7, 1.1, 1.7, 2.3}) {
    const std::vector<bool> r = person.Reaching(t);
    ASSERT_EQ(r.size(), 9u);
    EXPECT_TRUE(r[8]) << "t=" << t;
    EXPECT_EQ(std::count(r.begin(), r.end(), true), 1) << "t=" << t;
  }
  for (double t : {0.85, 1.9}) EXPECT_FALSE(person.Reaching(t)[8]) << "holding, t=" << t;
  // Assembling and idling (after the 0.5 s blend) are not reaching.
  for (double t : {4.2, 6.0, 11.0}) {
    const std::vector<bool> r = person.Reaching(t);
    EXPECT_EQ(std::count(r.begin(), r.end(), true), 0) << "t=" << t;
  }
}

TEST(SyntheticPerson, EpisodesPlayTheScriptWithEachFramesActionAndReaching) {
  SyntheticPersonParams p = CellPerson();
  p.noise_stddev = 0.01;
  const intent::SkeletonDataset d = RecordEpisodes(p, 2, 2, 1.0, 1.0, 10.0);
  ASSERT_EQ(d.sequences.size(), 4u);
  for (const auto& s : d.sequences) {
    const int n = static_cast<int>(s.time.size());
    EXPECT_EQ(n, 141);  // (1 + 12 + 1) s at 10 Hz, both ends
    ASSERT_EQ(s.frame_actions.size(), static_cast<size_t>(n));
    ASSERT_EQ(s.reaching.rows(), n);
    ASSERT_EQ(s.reaching.cols(), 9);
    EXPECT_EQ(s.action, "reach_parts");
    EXPECT_EQ(s.frame_actions[5], "idle");          // 0.5 s: before the start
    EXPECT_EQ(s.frame_actions[30], "reach_parts");  // 3 s
    EXPECT_EQ(s.frame_actions[80], "assemble");     // 8 s
    EXPECT_EQ(s.frame_actions[135], "idle");        // 13.5 s
    int reaching = 0;
    for (int k = 0; k < n; ++k) {
      reaching += s.reaching.row(k).count();
      if (s.reaching.row(k).any()) {
        EXPECT_EQ(s.frame_actions[k], "reach_parts") << "frame " << k;
      }
    }
    EXPECT_GT(reaching, 15);  // most of the 4 s of reaching (pace varies)
  }
  EXPECT_NE(d.sequences[0].positions, d.sequences[2].positions);  // two people
  EXPECT_EQ(RecordEpisodes(p, 2, 2, 1.0, 1.0, 10.0).sequences[3].positions, d.sequences[3].positions);
  SyntheticPersonParams no_script = p;
  no_script.script.clear();
  EXPECT_THROW(RecordEpisodes(no_script, 1, 1, 1.0, 1.0, 10.0), std::invalid_argument);
}

}  // namespace
}  // namespace iplan::perception

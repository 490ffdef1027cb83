// The demo's audit of protective stops against the true person: the
// stops' timeline (StopAudit) and the monitor's separation rule on the
// truth (TrueSeparationJudge).
#include "stop_audit.h"

#include <cmath>

#include <gtest/gtest.h>

namespace iplan::cli {
namespace {

constexpr int64_t kSec = 1000000000;

TEST(StopAudit, AStopThatOutlastsThePersonWithinSpCountsTheRest) {
  StopAudit a;
  a.Judge(9.5, true);   // within S_p before the stop
  a.StopStarted(10.0, "collision_risk: separation");
  a.Judge(11.0, false);  // out of S_p 1 s into the stop
  a.Judge(11.5, false);
  a.StopEnded(13.0);
  ASSERT_EQ(a.stops().size(), 1u);
  const AuditedStop& s = a.stops()[0];
  EXPECT_DOUBLE_EQ(s.Duration(), 3.0);
  EXPECT_DOUBLE_EQ(s.true_inside_s, 1.0);
  EXPECT_DOUBLE_EQ(s.last_inside_s, 11.0);
  EXPECT_DOUBLE_EQ(s.Outlast(), 2.0);
  EXPECT_DOUBLE_EQ(s.After(), 2.0);
  EXPECT_EQ(s.reason, "collision_risk: separation");
  EXPECT_EQ(a.judgements(), 3);
}

TEST(StopAudit, AStopWithThePersonNeverWithinSpIsAllExcess) {
  StopAudit a;
  a.Judge(0.0, false);
  a.StopStarted(1.0, "r");
  a.Judge(1.5, false);
  a.StopEnded(2.25);
  ASSERT_EQ(a.stops().size(), 1u);
  EXPECT_DOUBLE_EQ(a.stops()[0].true_inside_s, 0.0);
  EXPECT_TRUE(std::isinf(a.stops()[0].last_inside_s));
  EXPECT_DOUBLE_EQ(a.stops()[0].Outlast(), 1.25);
  EXPECT_DOUBLE_EQ(a.stops()[0].After(), 1.25);
}

TEST(StopAudit, AStopCalledBeforeThePersonIsWithinSpOutlastsTheirStayButNotAfterIt) {
  StopAudit a;
  a.StopStarted(1.0, "r");
  a.Judge(1.2, true);
  a.StopEnded(2.0);
  ASSERT_EQ(a.stops().size(), 1u);
  EXPECT_NEAR(a.stops()[0].true_inside_s, 0.8, 1e-12);
  EXPECT_NEAR(a.stops()[0].Outlast(), 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(a.stops()[0].After(), 0.0);
}

TEST(StopAudit, TheLastStretchWithinSpDecidesAndOldJudgementsAreIgnored) {
  StopAudit a;
  a.StopStarted(0.0, "r");
  a.Judge(0.0, true);
  a.Judge(0.5, false);
  a.Judge(0.25, true);  // older than the last: ignored
  a.Judge(1.0, true);
  a.Judge(1.25, false);
  a.StopEnded(3.0);
  ASSERT_EQ(a.stops().size(), 1u);
  EXPECT_DOUBLE_EQ(a.stops()[0].true_inside_s, 0.75);
  EXPECT_DOUBLE_EQ(a.stops()[0].last_inside_s, 1.25);
  EXPECT_DOUBLE_EQ(a.stops()[0].Outlast(), 2.25);
  EXPECT_DOUBLE_EQ(a.stops()[0].After(), 1.75);
  EXPECT_EQ(a.judgements(), 4);
}

TEST(StopAudit, OnlyEndedStopsAreListedAndAnEndWithoutAStartIsIgnored) {
  StopAudit a;
  a.StopEnded(1.0);
  a.StopStarted(2.0, "first");
  EXPECT_TRUE(a.stops().empty());
  a.StopStarted(3.0, "second");  // the first ends where the second starts
  a.StopEnded(4.0);
  ASSERT_EQ(a.stops().size(), 2u);
  EXPECT_DOUBLE_EQ(a.stops()[0].Duration(), 1.0);
  EXPECT_EQ(a.stops()[1].reason, "second");
}

TEST(StopAudit, TheSummaryLeavesOutTheSafeStartAndCountsStopsBeyondTheAllowance) {
  StopAudit a;
  a.StopStarted(0.0, "safe start");  // before the first task
  a.StopEnded(2.0);
  a.Judge(4.0, true);
  a.StopStarted(5.0, "within S_p, then 0.25 s more");
  a.Judge(6.0, false);
  a.StopEnded(6.25);
  a.StopStarted(8.0, "never within S_p");
  a.StopEnded(9.5);
  a.StopStarted(10.0, "0.5 s within S_p, then 0.75 s more");
  a.Judge(10.5, true);
  a.Judge(11.0, false);
  a.StopEnded(11.75);
  const StopAuditSummary s = Summarize(a, 3.0, 0.5);
  EXPECT_EQ(s.stops, 3);
  EXPECT_EQ(s.with_person_within, 2);
  // Outlasting the stay: 0.25, 1.5 and 1.25 s (0.5 s within S_p, 0.75 after).
  EXPECT_EQ(s.outlasting, 2);
  EXPECT_DOUBLE_EQ(s.allowance_s, 0.5);
  EXPECT_DOUBLE_EQ(s.outlast_p50_s, 1.25);
  EXPECT_DOUBLE_EQ(s.outlast_max_s, 1.5);
  EXPECT_DOUBLE_EQ(s.after_max_s, 1.5);
  EXPECT_EQ(Summarize(a, 20.0, 0.5).stops, 0);
  EXPECT_EQ(Describe(s),
            "3 after the safe start, 2 with the person within S_p; a stop outlasts their stay there by median 1.25 s, "
            "max 1.50 s (after they left: max 1.50 s); 2 by more than the resume delay (0.50 s); the person within "
            "S_p with no stop in force 1.00 s in all, at most 1.00 s at a time");
  EXPECT_EQ(Describe(a.stops()[1]), "at 5.0 s for 1.25 s (person within S_p 1.00 s, 0.25 s after they left)");
  EXPECT_EQ(Describe(a.stops()[2]), "at 8.0 s for 1.50 s (person never within S_p)");
}

TEST(StopAudit, TimeWithinSpWithNoStopInForceIsCountedInStretches) {
  StopAudit a;
  a.Judge(1.0, true);
  a.Judge(1.5, false);  // 0.5 s within S_p, no stop
  a.Judge(2.0, true);
  a.StopStarted(2.25, "r");  // 0.25 s, then the stop
  a.StopEnded(3.0);  // ended with the person still within S_p: 1 s more until 4.0
  a.Judge(3.5, true);
  a.Judge(4.0, false);
  EXPECT_DOUBLE_EQ(a.unstopped_inside_s(), 1.75);
  // The stretch before the stop does not add up with the one after it.
  EXPECT_DOUBLE_EQ(a.longest_unstopped_inside_s(), 1.0);
  ASSERT_EQ(a.stops().size(), 1u);
  EXPECT_DOUBLE_EQ(a.stops()[0].true_inside_s, 0.75);
  EXPECT_DOUBLE_EQ(a.stops()[0].After(), 0.0);
}

const std::vector<std::string> kJoints = {"head", "neck", "torso", "shoulder_l", "elbow_l", "hand_l",
                                          "shoulder_r", "elbow_r", "hand_r"};
const std::vector<std::string> kRobotJoints = {"panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4",
                                               "panda_joint5", "panda_joint6", "panda_joint7"};
const std::vector<double> kReady = {0, -0.785, 0, -2.356, 0, 1.571, 0.785};

// An upright person with the torso at `torso`, facing -x, the right hand
// 0.3 m in front of it.
std::vector<Eigen::Vector3d> Person(const Eigen::Vector3d& torso) {
  return {torso + Eigen::Vector3d(0, 0, 0.48), torso + Eigen::Vector3d(0, 0, 0.30), torso,
          torso + Eigen::Vector3d(0, -0.18, 0.25), torso + Eigen::Vector3d(-0.1, -0.2, 0.0),
          torso + Eigen::Vector3d(-0.25, -0.2, -0.05), torso + Eigen::Vector3d(0, 0.18, 0.25),
          torso + Eigen::Vector3d(-0.1, 0.2, 0.05), torso + Eigen::Vector3d(-0.3, 0.1, 0.0)};
}

class TrueSeparationJudgeTest : public ::testing::Test {
 protected:
  TrueSeparationJudgeTest()
      : judge_(collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml"),
               collision::HumanBodyParams::DefaultUpperBody(), Params()) {}
  // The cell's monitor as configured would take an unforecast person at
  // the default speed; the judge must not.
  static collision_risk::RiskParams Params() {
    collision_risk::RiskParams p;
    p.ssm.measure_human_speed = false;
    p.ssm.degrade_without_prediction = true;
    p.person_required = true;
    return p;
  }
  // The true person at 30 Hz from t - 0.2 s to t, the torso moving with
  // `v` and reaching `torso` at t.
  void Walk(int64_t t, const Eigen::Vector3d& torso, const Eigen::Vector3d& v) {
    for (int k = 6; k >= 0; --k) {
      const double back = k / 30.0;
      ASSERT_EQ(judge_.UpdateTruth(t - static_cast<int64_t>(back * kSec), kJoints, Person(torso - v * back)),
                std::nullopt);
    }
  }
  TrueSeparationJudge judge_;
};

TEST_F(TrueSeparationJudgeTest, NothingIsJudgedWithoutTheRobotOrTheTruth) {
  const int64_t t = 100 * kSec;
  EXPECT_EQ(judge_.Inside(t), std::nullopt);
  ASSERT_EQ(judge_.UpdateRobotState(t, kRobotJoints, kReady), std::nullopt);
  EXPECT_EQ(judge_.Inside(t), std::nullopt);
  Walk(t, {2.0, 0, 0.55}, Eigen::Vector3d::Zero());
  EXPECT_EQ(judge_.Inside(t), std::optional<bool>(false));
  // Two seconds later neither input is fresh.
  EXPECT_EQ(judge_.Inside(t + 2 * kSec), std::nullopt);
}

TEST_F(TrueSeparationJudgeTest, NoJudgementBeforeTheTruthGivesASpeed) {
  // A truth at 10 Hz: one pose, then 0.1 s of them, are less than half the
  // monitor's 0.3 s speed window, where it would take the default speed.
  const int64_t t = 100 * kSec;
  ASSERT_EQ(judge_.UpdateRobotState(t, kRobotJoints, kReady), std::nullopt);
  const Eigen::Vector3d torso(1.0, 0, 0.55);
  ASSERT_EQ(judge_.UpdateTruth(t - kSec / 10, kJoints, Person(torso)), std::nullopt);
  EXPECT_EQ(judge_.Inside(t - kSec / 10), std::nullopt);
  ASSERT_EQ(judge_.UpdateTruth(t, kJoints, Person(torso)), std::nullopt);
  EXPECT_EQ(judge_.Inside(t), std::nullopt);
  ASSERT_EQ(judge_.UpdateTruth(t + kSec / 10, kJoints, Person(torso)), std::nullopt);
  ASSERT_EQ(judge_.Inside(t + kSec / 10), std::optional<bool>(false));
  EXPECT_NEAR(judge_.last_report().human_speed, 0.0, 1e-9);
}

TEST_F(TrueSeparationJudgeTest, ThePersonsTrueSpeedTowardsTheRobotDecides) {
  const int64_t t = 100 * kSec;
  ASSERT_EQ(judge_.UpdateRobotState(t, kRobotJoints, kReady), std::nullopt);
  const Eigen::Vector3d torso(1.0, 0, 0.55);
  Walk(t, torso, Eigen::Vector3d::Zero());
  ASSERT_EQ(judge_.Inside(t), std::optional<bool>(false));
  const collision_risk::RiskReport still = judge_.last_report();
  ASSERT_TRUE(still.binding_separation.has_value());
  EXPECT_NEAR(still.human_speed, 0.0, 1e-9);  // measured, not the default 1.6 m/s
  EXPECT_GT(*still.binding_separation, still.protective_separation);

  // The same place, walking at the robot at 1.2 m/s: within S_p.
  Walk(t + kSec, torso, {-1.2, 0, 0});
  ASSERT_EQ(judge_.UpdateRobotState(t + kSec, kRobotJoints, kReady), std::nullopt);
  ASSERT_EQ(judge_.Inside(t + kSec), std::optional<bool>(true));
  const collision_risk::RiskReport walking = judge_.last_report();
  EXPECT_NEAR(walking.human_speed, 1.2, 0.05);
  EXPECT_LT(*walking.binding_separation, walking.protective_separation);
}

}  // namespace
}  // namespace iplan::cli

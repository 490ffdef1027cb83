// Several people, end to end with real processes (Fast DDS): perception's
// synthetic people (perception.synthetic.more_people), intent predicting
// each body, the collision-risk monitor and the robot simulator, with the
// shipped configuration. The first person stands far from the robot; the
// collision-risk monitor lets the robot move. A second person standing
// close to the robot stops it although the first one is still far away,
// and the monitor names the second body.
#include <iostream>
#include <set>

#include <gtest/gtest.h>

#include "cell_harness.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;

struct Observed {
  std::vector<msg::CollisionRisk> risks;
  std::set<uint32_t> predicted_bodies;
  std::string people;  // collision_risk's diagnostics value "people"
};

// Starts the partial cell with `people` (the --set value of more_people) and
// records collision risks and predicted bodies for 4 s from the monitor's
// first evaluation with a skeleton and a prediction.
Observed RunCell(const std::string& tag, const std::string& people) {
  Observed o;
  CellHarness cell("people-" + tag, dds::Vendor::kFastDds, 93);
  EXPECT_TRUE(cell.ready());
  if (!cell.ready()) return o;
  using SI = const dds::SampleInfo&;
  framework::SubscribeOptions any_order{false};
  bool recording = false;
  cell.node().Subscribe(framework::topics::CollisionRisk(),
                        std::function<void(const msg::CollisionRisk&, SI)>([&](const msg::CollisionRisk& r, SI) {
                          // From the first evaluation with a skeleton (separation < 1e6, "none")
                          // and a prediction: DDS discovery decides what arrives first.
                          if (msg::ToNanoseconds(r.prediction_stamp) > 0 && r.min_separation < 1e5) recording = true;
                          if (recording) o.risks.push_back(r);
                        }),
                        any_order);
  cell.node().Subscribe(framework::topics::HumanPrediction(),
                        std::function<void(const msg::HumanPrediction& m, SI)>(
                            [&](const msg::HumanPrediction& m, SI) { o.predicted_bodies.insert(m.body_id); }),
                        any_order);
  // The first person idles 2.6 m from the robot's base; the others where
  // `people` puts them.
  // The robot first, so that the monitor knows its state before it sees anyone.
  cell.Start("robot_sim");
  cell.Start("collision_risk");
  EXPECT_TRUE(cell.SpinUntil([&] { return !cell.positions().empty(); }, 20s)) << cell.Logs("robot_sim");
  cell.SpinFor(500ms);
  cell.Start("perception", {"--set", "perception.synthetic.start=loop", "--set", "perception.synthetic.script=[idle]",
                            "--set", "perception.synthetic.durations=[5.0]", "--set",
                            "perception.synthetic.torso=[2.6, 0.0, 0.25]", "--set",
                            "perception.synthetic.more_people=" + people});
  cell.Start("intent");
  EXPECT_TRUE(cell.SpinUntil([&] { return recording; }, 30s)) << cell.Logs("collision_risk") << cell.Logs("intent");
  cell.SpinFor(4s);
  o.people = cell.Diag("collision_risk", "people");
  return o;
}

// How many evaluations had `verdict`, and their distinct reasons.
int Count(const std::vector<msg::CollisionRisk>& risks, uint8_t verdict, std::string* reasons = nullptr) {
  int n = 0;
  std::set<std::string> why;
  for (const auto& r : risks) {
    if (r.verdict != verdict) continue;
    ++n;
    why.insert(r.reason);
  }
  for (const auto& w : why) {
    if (reasons) *reasons += w + "\n";
  }
  return n;
}

TEST(People, ASecondPersonCloseToTheRobotStopsItThoughTheFirstIsFarAway) {
  const Observed one = RunCell("one", "[]");
  ASSERT_GT(one.risks.size(), 20u);
  EXPECT_EQ(one.predicted_bodies, (std::set<uint32_t>{1}));
  EXPECT_EQ(one.people, "1 seen, 1 predicted");
  // Alone and far, the person lets the robot move: no stop, at most a slow-down.
  std::string reasons;
  EXPECT_EQ(Count(one.risks, msg::CollisionRisk::PROTECTIVE_STOP, &reasons), 0) << reasons;
  EXPECT_GT(one.risks.back().min_separation, 1.5);

  // Body 2 stands 0.62 m in front of the robot's base, body 1 still 2.6 m away.
  const Observed two = RunCell("two", "[{torso: [0.62, 0.0, 0.25], seed: 5}]");
  ASSERT_GT(two.risks.size(), 20u);
  EXPECT_EQ(two.predicted_bodies, (std::set<uint32_t>{1, 2})) << "intent predicts each body";
  EXPECT_EQ(two.people, "2 seen, 2 predicted");
  // After the first second every evaluation stops the robot, because of body 2.
  int late = 0, stops = 0, naming = 0;
  const int64_t first = msg::ToNanoseconds(two.risks.front().header.stamp);
  for (const auto& r : two.risks) {
    if (msg::ToNanoseconds(r.header.stamp) - first < 1'000'000'000) continue;
    ++late;
    stops += r.verdict == msg::CollisionRisk::PROTECTIVE_STOP;
    naming += r.reason.find("body 2") != std::string::npos;
  }
  ASSERT_GT(late, 20);
  EXPECT_EQ(stops, late) << two.risks.back().reason;
  EXPECT_EQ(naming, late) << two.risks.back().reason;
  EXPECT_LT(two.risks.back().min_separation, 0.5);
  std::cout << "one person: " << one.risks.size() << " evaluations, last: " << one.risks.back().reason
            << " (separation " << one.risks.back().min_separation << " m)\ntwo people: " << two.risks.size()
            << " evaluations, " << stops << " of the last " << late << " stops, last: " << two.risks.back().reason << "\n";
}

}  // namespace
}  // namespace iplan::testing

// The benchmark's scenarios on the shipped cell (config/, the recorded
// motion of ../shared/data/assembly.csv): the default suite draws exactly
// the scenarios it drew before the shared-space suite existed; the
// shared-space suite covers its four kinds in 8 scenarios, every one with
// the person within reach of the robot's path (rechecked here), the same
// for a seed; PathDistance measures what it says; the summary splits the
// contacts. Drawing needs no trained intent model (only running does), so
// the setup carries an empty one.
#include "tools/cell_sim/core/interaction_benchmark.h"

#include <algorithm>
#include <memory>
#include <set>

#include <gtest/gtest.h>

#include "tools/cell_sim/cell_config.h"
#include "iplan/collision/robot_model.h"
#include "iplan/intent/skeleton_data.h"

namespace iplan::cell_sim {
namespace {

class InteractionBenchmarkTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    cell_ = new CellConfig(LoadCellConfig(std::string(IPLAN_SOURCE_DIR) + "/config", 1));
    recordings_ = new intent::SkeletonDataset(
        intent::LoadSkeletonCsv(std::string(IPLAN_SHARED_DIR) + "/data/assembly.csv"));
  }
  static void TearDownTestSuite() {
    delete cell_;
    delete recordings_;
  }

  // As `iplan eval interaction` sets it up, without the trained model.
  BenchmarkSetup Setup() const {
    BenchmarkSetup s = cell_->MakeSetup();
    s.intent_model = std::make_shared<const intent::IntentModel>();
    s.recordings = recordings_;
    s.recordings_file = "assembly.csv";
    s.joint_map = {{"wrist_l", "hand_l"}, {"wrist_r", "hand_r"}};
    return s;
  }

  // A person holding one pose: every joint at p_W, for `seconds` at 30 Hz.
  PersonStream AllAt(const Eigen::Vector3d& p_W, double seconds) const {
    PersonStream s;
    s.joint_names = cell_->body->params().joints;
    s.rate_hz = 30;
    const Eigen::Matrix3Xd pose = p_W.replicate(1, static_cast<Eigen::Index>(s.joint_names.size()));
    for (int i = 0; i <= static_cast<int>(seconds * 30); ++i) s.truth.push_back(pose);
    s.observed = s.truth;
    return s;
  }

  static CellConfig* cell_;
  static intent::SkeletonDataset* recordings_;
};

CellConfig* InteractionBenchmarkTest::cell_ = nullptr;
intent::SkeletonDataset* InteractionBenchmarkTest::recordings_ = nullptr;

// Drawn by MakeScenarios(setup, 8, seed) at commit 8c1a000, before the
// suites (the shipped configuration and assembly.csv).
struct DrawnBefore {
  uint64_t seed;
  int index;
  uint64_t noise_seed;
  std::string source, subject, sequence;
  Eigen::Vector3d placement_W;
  double yaw, clip_start, delay;
  std::string task, start;
};

const std::vector<DrawnBefore>& Before() {
  static const std::vector<DrawnBefore> kBefore = {
      {1, 0, 16091060326050219876ULL, "recorded", "human1", "task4_human1_trial2",
       {1.138327705275769, 0.18949148872799793, 0.5}, 0.028853027431653966, 11.0233229856946, 0.30449346229721042,
       "hand_over", "fetch_right"},
      {1, 1, 8244590278581434897ULL, "recorded", "human2", "task5_human2_trial2",
       {1.2022424273469376, -0.078199583192051281, 0.5}, -0.029732665203473563, 16.603861687555934,
       0.95218852065456439, "reach", "home"},
      {1, 2, 1963315426409818498ULL, "synthetic", "synthetic", "reach_parts,assemble,idle",
       {1.2093856681700399, 0.13858814054087976, 0.25}, 0.16809961719354244, 0, 1.4906412707700163, "fetch_right",
       "hand_over"},
      {1, 3, 12455319262754003858ULL, "synthetic", "synthetic", "reach_parts,assemble,idle",
       {1.1916179225709855, 0.036451470315517487, 0.25}, -0.0088519911340814716, 0, -4.4442764189212323, "reach",
       "hand_over.retreat"},
      {7, 4, 6089644492459887159ULL, "recorded", "human1", "task3_human1_trial1",
       {1.0566806605127697, 0.20977245581152432, 0.5}, 0.065156339038008715, 18.861486717895311, 1.010737270539569,
       "fetch_right", "home"},
      {7, 7, 17857032714138445296ULL, "synthetic", "synthetic", "reach_parts,assemble,idle",
       {1.3371236703246594, -0.041051327753891143, 0.25}, -0.12585223330366457, 0, -0.28460228529412568, "reach",
       "hand_over"},
  };
  return kBefore;
}

TEST_F(InteractionBenchmarkTest, TheDefaultSuiteDrawsWhatItDrewBefore) {
  const BenchmarkSetup setup = Setup();
  for (uint64_t seed : {1ULL, 7ULL}) {
    const std::vector<ScenarioSpec> plain = MakeScenarios(setup, 8, seed);
    const std::vector<ScenarioSpec> named = MakeScenarios(setup, 8, seed, Suite::kDefault);
    ASSERT_EQ(plain.size(), 8u);
    ASSERT_EQ(named.size(), 8u);
    for (std::size_t i = 0; i < plain.size(); ++i) {
      EXPECT_EQ(plain[i].seed, named[i].seed);
      EXPECT_EQ(plain[i].placement_W, named[i].placement_W);
      EXPECT_EQ(plain[i].goal_q, named[i].goal_q);
      // Nothing of the shared-space suite.
      EXPECT_EQ(plain[i].kind, "");
      EXPECT_FALSE(plain[i].path_distance.has_value());
      EXPECT_TRUE(plain[i].person_actions.empty() && plain[i].person_script.empty());
      EXPECT_FALSE(plain[i].sweep.has_value());
    }
    for (const DrawnBefore& b : Before()) {
      if (b.seed != seed) continue;
      SCOPED_TRACE("seed " + std::to_string(seed) + " scenario " + std::to_string(b.index));
      const ScenarioSpec& s = plain[static_cast<std::size_t>(b.index)];
      EXPECT_EQ(s.index, b.index);
      EXPECT_EQ(s.seed, b.noise_seed);
      EXPECT_EQ(s.source, b.source);
      EXPECT_EQ(s.subject, b.subject);
      EXPECT_EQ(s.sequence, b.sequence);
      EXPECT_EQ(s.placement_W, b.placement_W);  // bit for bit
      EXPECT_EQ(s.yaw, b.yaw);
      EXPECT_EQ(s.clip_start, b.clip_start);
      EXPECT_EQ(s.delay, b.delay);
      EXPECT_EQ(s.task, b.task);
      EXPECT_EQ(s.start, b.start);
      if (s.task != "reach") {
        const auto t = std::find_if(setup.tasks.begin(), setup.tasks.end(), [&](const GraphTask& g) { return g.name == s.task; });
        ASSERT_NE(t, setup.tasks.end());
        EXPECT_EQ(s.goal_q, t->goal);
      }
    }
  }
}

TEST_F(InteractionBenchmarkTest, TheDefaultSuiteReachesAreWhereTheyWereBefore) {
  // The first table-top point of the draws the planner's IK solves (clear of
  // the scene): these move only if the IK's answers do (common/planning).
  const std::vector<ScenarioSpec> specs = MakeScenarios(Setup(), 4, 1);
  EXPECT_EQ(specs[1].reach_p_WE, Eigen::Vector3d(0.63949294863198525, -0.091443140834567616, 0.3116966858003013));
  EXPECT_EQ(specs[3].reach_p_WE, Eigen::Vector3d(0.59303664830929359, 0.055277098435534799, 0.28072541498029457));
}

TEST_F(InteractionBenchmarkTest, SharedSpaceCoversItsFourKindsWithThePersonWithinReachOfThePath) {
  const BenchmarkSetup setup = Setup();
  const std::vector<ScenarioSpec> specs = MakeScenarios(setup, 8, 1, Suite::kSharedSpace);
  ASSERT_EQ(specs.size(), 8u);
  std::map<std::string, int> kinds;
  std::set<std::string> subjects;
  for (const ScenarioSpec& s : specs) {
    SCOPED_TRACE("scenario " + std::to_string(s.index) + " " + s.kind);
    ++kinds[s.kind];
    // Kind i % 4; the synthetic person in 0-3, recorded motion in 4-7.
    EXPECT_EQ(s.kind, SharedSpaceKinds()[static_cast<std::size_t>(s.index % 4)]);
    EXPECT_EQ(s.source, s.index < 4 ? "synthetic" : "recorded");
    if (s.source == "recorded") subjects.insert(s.subject);
    // The robot's task of the kind.
    if (s.kind == "hand-over") {
      EXPECT_EQ(s.task, "hand_over");
    }
    if (s.kind == "parts-bin") {
      EXPECT_EQ(s.task, "fetch_left");
    }
    if (s.kind == "co-assembly") {
      EXPECT_EQ(s.task, "reach");
      EXPECT_EQ(s.shared_point_W, s.reach_p_WE);
    }
    EXPECT_EQ(s.sweep.has_value(), s.kind == "crossing" && s.source == "synthetic");
    if (s.sweep) {
      // Mid-task: halfway along the line 0.6-2.2 s after the command.
      EXPECT_GE(s.sweep->middle(), setup.loop.task_start + 0.6 - 1e-9);
      EXPECT_LE(s.sweep->middle(), setup.loop.task_start + 2.2 + 1e-9);
      EXPECT_NEAR((0.5 * (s.sweep->from_W + s.sweep->to_W) - s.shared_point_W).head<2>().norm(), 0.0, 1e-9);
    }
    // Within reach of the path, and the figure is what it claims to be.
    ASSERT_TRUE(s.path_distance.has_value());
    EXPECT_LT(*s.path_distance, setup.shared_space.max_path_distance);
    EXPECT_EQ(*s.path_distance, ScenarioPathDistance(setup, s));
    EXPECT_GE(s.draws, 1);
    EXPECT_LE(s.draws, setup.shared_space.max_draws);
    // A synthetic person of the kind does the kind's action.
    if (s.source == "synthetic" && s.kind != "crossing") {
      ASSERT_FALSE(s.person_actions.empty());
      ASSERT_FALSE(s.person_script.empty());
      EXPECT_EQ(s.person_script.front().action, s.person_actions.front().name);
      const std::string expected = s.kind == "hand-over" ? "reach_hand_over" : s.kind == "parts-bin" ? "reach_parts" : "assemble";
      EXPECT_EQ(s.person_actions.front().name, expected);
    }
  }
  EXPECT_EQ(kinds, (std::map<std::string, int>{{"hand-over", 2}, {"parts-bin", 2}, {"co-assembly", 2}, {"crossing", 2}}));
  EXPECT_EQ(subjects, (std::set<std::string>{"human1", "human2"}));
}

TEST_F(InteractionBenchmarkTest, SharedSpaceHoldsTheThresholdForOtherSeedsToo) {
  const BenchmarkSetup setup = Setup();
  for (uint64_t seed : {2ULL, 3ULL, 42ULL}) {
    for (const ScenarioSpec& s : MakeScenarios(setup, 8, seed, Suite::kSharedSpace)) {
      ASSERT_TRUE(s.path_distance.has_value());
      EXPECT_LT(*s.path_distance, 0.35) << "seed " << seed << " scenario " << s.index;
    }
  }
}

TEST_F(InteractionBenchmarkTest, SharedSpaceIsTheSameForASeed) {
  const BenchmarkSetup setup = Setup();
  const std::vector<ScenarioSpec> a = MakeScenarios(setup, 8, 5, Suite::kSharedSpace);
  const std::vector<ScenarioSpec> b = MakeScenarios(setup, 8, 5, Suite::kSharedSpace);
  const std::vector<ScenarioSpec> first = MakeScenarios(setup, 3, 5, Suite::kSharedSpace);  // k is k whatever the count
  const std::vector<ScenarioSpec> other = MakeScenarios(setup, 8, 6, Suite::kSharedSpace);
  ASSERT_EQ(a.size(), b.size());
  int differs = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("scenario " + std::to_string(i));
    for (const ScenarioSpec* x : {&b[i], i < first.size() ? &first[i] : &b[i]}) {
      EXPECT_EQ(a[i].seed, x->seed);
      EXPECT_EQ(a[i].kind, x->kind);
      EXPECT_EQ(a[i].source, x->source);
      EXPECT_EQ(a[i].sequence, x->sequence);
      EXPECT_EQ(a[i].placement_W, x->placement_W);
      EXPECT_EQ(a[i].yaw, x->yaw);
      EXPECT_EQ(a[i].delay, x->delay);
      EXPECT_EQ(a[i].clip_start, x->clip_start);
      EXPECT_EQ(a[i].start_q, x->start_q);
      EXPECT_EQ(a[i].goal_q, x->goal_q);
      EXPECT_EQ(a[i].shared_point_W, x->shared_point_W);
      EXPECT_EQ(a[i].path_distance, x->path_distance);
      EXPECT_EQ(a[i].draws, x->draws);
      ASSERT_EQ(a[i].person_actions.size(), x->person_actions.size());
      for (std::size_t k = 0; k < a[i].person_actions.size(); ++k) {
        EXPECT_EQ(a[i].person_actions[k].target_W, x->person_actions[k].target_W);
      }
      ASSERT_EQ(a[i].sweep.has_value(), x->sweep.has_value());
      if (a[i].sweep) {
        EXPECT_EQ(a[i].sweep->from_W, x->sweep->from_W);
        EXPECT_EQ(a[i].sweep->start, x->sweep->start);
      }
    }
    differs += a[i].placement_W != other[i].placement_W;
  }
  EXPECT_GE(differs, 6) << "another seed should draw other scenarios";
}

TEST_F(InteractionBenchmarkTest, SharedSpaceRefusesACellWithoutItsTasksOrAnUnreachableThreshold) {
  BenchmarkSetup setup = Setup();
  setup.shared_space.max_path_distance = 0;
  try {
    MakeScenarios(setup, 4, 1, Suite::kSharedSpace);
    ADD_FAILURE() << "a threshold of 0 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_path_distance"), std::string::npos) << e.what();
  }
  // Not every scenario overlaps the path in its first draw: the first that
  // does not is named, with the nearest distance drawn.
  setup = Setup();
  setup.shared_space.max_path_distance = 1e-6;
  setup.shared_space.max_draws = 1;
  try {
    MakeScenarios(setup, 8, 1, Suite::kSharedSpace);
    ADD_FAILURE() << "every scenario overlapped the path in its first draw";
  } catch (const std::runtime_error& e) {
    const std::string why = e.what();
    EXPECT_NE(why.find("shared-space scenario "), std::string::npos) << why;
    EXPECT_NE(why.find("no draw of 1 brought the person within"), std::string::npos) << why;
    EXPECT_NE(why.find("(nearest "), std::string::npos) << why;
  }
  setup = Setup();
  setup.tasks.erase(std::remove_if(setup.tasks.begin(), setup.tasks.end(),
                                   [](const GraphTask& t) { return t.name == "hand_over"; }),
                    setup.tasks.end());
  try {
    MakeScenarios(setup, 4, 1, Suite::kSharedSpace);
    ADD_FAILURE() << "a graph without hand_over was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'hand_over'"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(MakeScenarios(setup, 4, 1, Suite::kDefault));  // the default suite does not need it
}

TEST_F(InteractionBenchmarkTest, PathDistanceIsTheSurfaceDistanceToTheNearestPathConfiguration) {
  const collision::RobotModel& robot = cell_->planner->robot();
  const collision::HumanBodyModel& body = *cell_->body;
  const Eigen::VectorXd home = cell_->tasks.back().goal;  // table_top.yaml's last task: home
  const auto hand_over = std::find_if(cell_->tasks.begin(), cell_->tasks.end(), [](const GraphTask& t) { return t.name == "hand_over"; });
  ASSERT_NE(hand_over, cell_->tasks.end());
  const Eigen::VectorXd goal = hand_over->goal;
  collision::RobotData data(robot);
  collision::CalcForwardKinematics(robot, goal, &data);
  double largest_human = 0;
  for (const auto& s : body.spheres()) largest_human = std::max(largest_human, s.radius);

  // Every joint at one point 1 m beyond the goal's first robot sphere, away
  // from the robot's base: the nearest pair is at most that far.
  const Eigen::Vector3d c = data.p_WS.col(data.p_WS.cols() - 1);
  const Eigen::Vector3d away = c + Eigen::Vector3d(c.x(), c.y(), 0).normalized();
  const double d_away = PathDistance(robot, body, home, goal, 21, AllAt(away, 2.0), 0.0, 2.0);
  EXPECT_LE(d_away, 1.0 - robot.spheres.back().radius - largest_human + 1e-12);
  EXPECT_GT(d_away, 0.5);
  // On the goal's sphere: overlapping by both radii.
  const double d_on = PathDistance(robot, body, home, goal, 21, AllAt(c, 2.0), 0.0, 2.0);
  EXPECT_LE(d_on, -robot.spheres.back().radius - largest_human + 1e-12);
  // Only the window counts: there until 0.9 s, far away after.
  PersonStream passing = AllAt(c, 3.0);
  const PersonStream gone = AllAt(Eigen::Vector3d(4, 0, 0), 3.0);
  for (int i = 28; i < passing.num_frames(); ++i) passing.truth[static_cast<std::size_t>(i)] = gone.truth[static_cast<std::size_t>(i)];
  passing.observed = passing.truth;
  EXPECT_LT(PathDistance(robot, body, home, goal, 21, passing, 0.0, 3.0), 0.0);
  EXPECT_GT(PathDistance(robot, body, home, goal, 21, passing, 1.0, 3.0), 2.5);
  // More samples can only come nearer.
  EXPECT_LE(PathDistance(robot, body, home, goal, 41, AllAt(away, 1.0), 0.0, 1.0),
            PathDistance(robot, body, home, goal, 3, AllAt(away, 1.0), 0.0, 1.0));
  // Bad input.
  EXPECT_THROW(PathDistance(robot, body, home, goal, 1, passing, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(PathDistance(robot, body, home, goal, 21, passing, 5.0, 6.0), std::invalid_argument);
  EXPECT_THROW(PathDistance(robot, body, home, Eigen::VectorXd::Zero(3), 21, passing, 0.0, 1.0), std::invalid_argument);
}

TEST(Summarize, SplitsTheContactsByWhatTheRobotWasDoing) {
  // Two scenarios, two predictors: contacts 1 moving + 1 at rest, 0, 2 moving, 1 at rest.
  auto run = [](int moving, int at_rest) {
    InteractionResult r;
    r.finished = true;
    r.status = trajopt::TaskStatus::kSucceeded;
    r.task_time = 3;
    r.robot_moving_contacts = moving;
    r.robot_at_rest_contacts = at_rest;
    r.true_contacts = moving + at_rest;
    return r;
  };
  const std::vector<std::vector<InteractionResult>> results = {{run(1, 1), run(0, 0)}, {run(2, 0), run(0, 1)}};
  const std::vector<PredictorSummary> s = Summarize({Predictor::kNone, Predictor::kModel}, results);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].true_contacts, 4);
  EXPECT_EQ(s[0].robot_moving_contacts, 3);
  EXPECT_EQ(s[0].robot_at_rest_contacts, 1);
  EXPECT_EQ(s[1].true_contacts, 1);
  EXPECT_EQ(s[1].robot_moving_contacts, 0);
  EXPECT_EQ(s[1].robot_at_rest_contacts, 1);
}

TEST(Suites, NamesRoundTrip) {
  EXPECT_EQ(SuiteNames(), (std::vector<std::string>{"default", "shared-space"}));
  for (const auto& n : SuiteNames()) EXPECT_EQ(ToString(*ParseSuite(n)), n);
  EXPECT_FALSE(ParseSuite("shared_space").has_value());
  EXPECT_EQ(SharedSpaceKinds(), (std::vector<std::string>{"hand-over", "parts-bin", "co-assembly", "crossing"}));
}

}  // namespace
}  // namespace iplan::cell_sim

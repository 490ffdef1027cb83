// A person seen only by the depth camera (issue 18 item 5):
// iplan-collision-risk (Fast DDS) and iplan-robot-sim (Cyclone DDS) as
// separate processes, the robot obeying only the collision-risk monitor's
// permit. This process plays trajopt (the arm reaching out and back) and the
// cloud stage: a participant named iplan-cloud (the topic's entitled writer)
// publishes /iplan/human/points of a person walking at the robot, and no
// skeleton or prediction at all. The robot must come to a protective stop
// before any contact with the points, and stay stopped while the person
// stands close.
#include <signal.h>

#include <cmath>
#include <cstdlib>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "iplan/collision/robot_model.h"
#include "iplan/framework/node.h"
#include "cell_harness.h"
#include "test_messages.h"
#include "test_node.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

const std::vector<double>& kReady = kPandaReady;
constexpr double kVoxel = 0.02;  // m, the points' grid (r_p = 1 cm)

// The side of a standing person the camera sees: a half cylinder of radius
// 0.15 m around the vertical axis at (x, 0), facing -x (the robot), z from
// 0.2 to 1.7 m, on a 2 cm grid (24 x 75 = 1,800 points).
Eigen::Matrix3Xd PersonPoints(double x) {
  Eigen::Matrix3Xd p(3, 24 * 75);
  for (int a = 0; a < 24; ++a) {
    const double phi = M_PI / 2 + M_PI * (a + 0.5) / 24;  // the -x half
    for (int h = 0; h < 75; ++h) p.col(a * 75 + h) = Eigen::Vector3d(x + 0.15 * std::cos(phi), 0.15 * std::sin(phi), 0.2 + 0.02 * h);
  }
  return p;
}

msg::HumanPoints PointsMessage(const Eigen::Matrix3Xd& p) {
  msg::HumanPoints m;
  m.header.stamp = msg::Now();
  m.header.frame_id = "world";
  m.voxel_size = kVoxel;
  m.points.resize(static_cast<std::size_t>(p.cols()));
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    auto& g = m.points[static_cast<std::size_t>(i)];
    g.mean = {p(0, i), p(1, i), p(2, i)};
    g.covariance = {6.4e-5, 0, 0, 0, 9e-6, 0, 0, 0, 9e-6};  // 8 mm along the camera's axis, 3 mm across
  }
  return m;
}

// The arm reaching out to kReach (its front at x = 0.74 m) and back to
// kReady, every 4 s, for 30 s.
const std::vector<double> kReach = {0, 0.3, 0, -1.5, 0, 1.9, 0.785};
constexpr double kFinalX = 0.8;  // m, where the person stops: the points' front at 0.65 m, in the arm's reach
std::vector<double> ReachAt(double t) {
  const double u = 0.5 - 0.5 * std::cos(2 * M_PI * t / 4.0);
  std::vector<double> q(7);
  for (std::size_t j = 0; j < 7; ++j) q[j] = (1 - u) * kReady[j] + u * kReach[j];
  return q;
}
msg::JointTrajectory Reaching(const msg::Time& start) { return SampledTrajectory(start, ReachAt, 30.0); }

struct State {
  double t;                    // s since the walk started
  std::vector<double> q, qd;
  double person_x;             // where the newest published points were
};
struct Risk {
  double t;
  msg::CollisionRisk r;
};

// Smallest surface distance (m) between the robot's spheres at q and the points (radius kVoxel / 2).
double Distance(const collision::RobotModel& robot, const std::vector<double>& q, const Eigen::Matrix3Xd& p) {
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, Eigen::Map<const Eigen::VectorXd>(q.data(), 7), &d);
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index k = 0; k < d.p_WS.cols(); ++k)
    for (Eigen::Index i = 0; i < p.cols(); ++i)
      best = std::min(best, (d.p_WS.col(k) - p.col(i)).norm() - robot.spheres[static_cast<std::size_t>(k)].radius - kVoxel / 2);
  return best;
}

struct Walk {
  std::vector<State> states;
  std::vector<Risk> risks;
};

// The cell with the person walking in: 2 s standing 2.3 m away (the robot
// reaches), then the walk at 0.5 m/s to kFinalX, then 3 s standing there.
// Times are s since the walk started.
Walk RunWalk(const std::string& risk_vendor) {
  CellHarness services("human-points-stop", dds::Vendor::kCyclone, 95, "", /*with_intent=*/false);
  const int domain = services.domain();
  Walk w;
  std::vector<State>& states = w.states;
  std::vector<Risk>& risks = w.risks;
  services.SetVendor("collision_risk", dds::ParseVendor(risk_vendor));
  services.Start("collision_risk", {"--set", "node.entitled_writers./iplan/robot/trajectory=[scripted_cell]"});
  services.Start("robot_sim", {"--set", "robot_sim.permits.monitors=[iplan-collision_risk]", "--set",
                               "node.entitled_writers./iplan/robot/trajectory=[scripted_cell]"});
  TestNode cell("scripted_cell", dds::Vendor::kCyclone, domain);
  TestNode cloud("iplan-cloud", dds::Vendor::kCyclone, domain);
  framework::Node& node = *cell.node;
  auto& traj = node.Advertise(framework::topics::RobotTrajectory());
  auto& points = cloud.node->Advertise(framework::topics::HumanPoints());
  Clock::time_point walk_start{};
  double person_x = 2.3;
  auto since = [&] { return std::chrono::duration<double>(Clock::now() - walk_start).count(); };
  node.Subscribe(framework::topics::JointStates(),
                 std::function<void(const msg::JointState&, const dds::SampleInfo&)>(
                     [&](const msg::JointState& m, const dds::SampleInfo&) {
                       if (walk_start != Clock::time_point{}) states.push_back({since(), m.position, m.velocity, person_x});
                     }));
  node.Subscribe(framework::topics::CollisionRisk(),
                 std::function<void(const msg::CollisionRisk&, const dds::SampleInfo&)>(
                     [&](const msg::CollisionRisk& r, const dds::SampleInfo&) {
                       if (walk_start != Clock::time_point{}) risks.push_back({since(), r});
                     }));
  const auto up = Clock::now() + 30s;
  while (Clock::now() < up && (traj.MatchedReaders() < 2 || points.MatchedReaders() == 0)) node.SpinOnce(20ms);
  // Both services read the trajectory (a Fast DDS reader also brings its
  // liveliness watch reader, docs/dds.md: 2 or more).
  EXPECT_GE(traj.MatchedReaders(), 2) << services.Logs("collision_risk") << services.Logs("robot_sim");
  traj.Write(Reaching(msg::Now()));
  const auto t0 = Clock::now();
  auto next_points = t0;
  while (Clock::now() - t0 < 9s) {
    const double t = std::chrono::duration<double>(Clock::now() - t0).count();
    if (t >= 2.0 && walk_start == Clock::time_point{}) walk_start = Clock::now();
    if (Clock::now() >= next_points) {
      person_x = std::max(kFinalX, 2.3 - 0.5 * std::max(0.0, t - 2.0));
      points.Write(PointsMessage(PersonPoints(person_x)));
      next_points += 66ms;
    }
    node.SpinOnce(5ms);
  }
  services.Stop();
  if (std::getenv("IPLAN_TEST_VERBOSE")) std::cout << services.Logs("collision_risk") << "\n";  // the monitor's log, to debug
  return w;
}

TEST(HumanPointsStop, APersonSeenOnlyAsPointsStopsTheRobotBeforeContact) {
  const auto [states, risks] = RunWalk("fastdds");

  // Without a stop the reaching arm would go through the standing person's points.
  double unstopped = std::numeric_limits<double>::infinity();
  const collision::RobotModel robot =
      collision::LoadRobotModelFromYaml(std::string(IPLAN_SOURCE_DIR) + "/config/robots/panda.yaml");
  for (int i = 0; i <= 40; ++i) unstopped = std::min(unstopped, Distance(robot, ReachAt(0.1 * i), PersonPoints(kFinalX)));
  EXPECT_LT(unstopped, -0.05);
  ASSERT_GT(risks.size(), 50u);
  ASSERT_GT(states.size(), 100u);
  // The robot sweeps under an OK verdict while the person is far.
  // (A verdict may stop for points that came late: safe, and not the point.)
  int early_ok = 0;
  for (const Risk& r : risks) early_ok += r.t < 1.0 && r.r.verdict == msg::CollisionRisk::OK;
  EXPECT_GE(early_ok, 5) << risks.front().r.reason;
  double early_speed = 0;
  for (const State& s : states)
    if (s.t < 1.5) early_speed = std::max(early_speed, std::abs(s.qd[1]));
  EXPECT_GT(early_speed, 0.2);
  // The first stop for the points' separation (a stop because the points
  // were late, a "person no longer tracked", is safe too, but not the point).
  const Risk* stop = nullptr;
  int stale_stops = 0;
  for (const Risk& r : risks) {
    if (r.r.verdict != msg::CollisionRisk::PROTECTIVE_STOP) continue;
    if (r.r.reason.find("/ points)") == std::string::npos) {
      ++stale_stops;
      continue;
    }
    stop = &r;
    break;
  }
  ASSERT_NE(stop, nullptr) << "never stopped for the points";
  double risk_gap = 0;  // the monitor's longest silence: > stale_after means it was starved, not the points lost
  for (std::size_t i = 1; i < risks.size(); ++i) risk_gap = std::max(risk_gap, risks[i].t - risks[i - 1].t);
  std::cout << "longest gap between collision-risk messages " << risk_gap << " s\n";
  std::cout << "first protective stop for the points at +" << stop->t << " s (" << stale_stops
            << " stops before for late points): separation " << stop->r.min_separation << " m, S_p "
            << stop->r.protective_separation << " m: " << stop->r.reason << "\n";
  EXPECT_GT(stop->r.min_separation, 0.3);
  // Every later verdict is a stop (the person comes and stays within S_p).
  for (const Risk& r : risks) {
    if (r.t > stop->t) {
      EXPECT_EQ(r.r.verdict, msg::CollisionRisk::PROTECTIVE_STOP) << "+" << r.t << ": " << r.r.reason;
    }
  }
  // The robot is at rest within its stopping time (0.3 s) plus a permit's
  // validity and delivery (0.3 s), and never touches the points.
  double closest = std::numeric_limits<double>::infinity(), late_speed = 0;
  for (const State& s : states) {
    closest = std::min(closest, Distance(robot, s.q, PersonPoints(s.person_x)));
    if (s.t > stop->t + 0.6)
      for (double v : s.qd) late_speed = std::max(late_speed, std::abs(v));
  }
  std::cout << "closest robot-points distance " << closest << " m; joint speed after the stop " << late_speed
            << " rad/s\n";
  EXPECT_GT(closest, 0.0);
  EXPECT_LT(late_speed, 1e-6);
}

}  // namespace
}  // namespace iplan::testing

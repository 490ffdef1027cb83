// The whole depth-camera chain as real processes, no test-published
// intermediate topic (issue 18's multi-process "done when"):
//
// 1. A person seen only by the depth camera: iplan-perception renders the
//    synthetic person in the simulated camera and publishes NO skeleton
//    (perception.publish_skeleton=false: a person the tracker lost);
//    iplan-cloud makes /iplan/human/points; iplan-collision-risk must stop
//    iplan-robot-sim (which obeys only collision risk's permit) before the
//    person's hand, reaching into the arm's path, is touched. This process
//    plays trajopt (one scripted reach of the arm) and the supervisor's
//    episode start (the person's script begins with it); contact is judged
//    against the true body (/iplan/sim/human_truth) and the robot's spheres.
// 2. A box that appears on the table while the cell runs, rendered by the
//    simulated camera only (perception.depth.simulated.added_scenes /
//    added_after): iplan-cloud -> /iplan/obstacles -> iplan-trajopt; the
//    executed joint states of iplan-robot-sim never put a robot sphere into
//    the true box (FCL). This process commands the task and grants permits.
#include <signal.h>

#include <cmath>
#include <fstream>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "iplan/collision/human_model.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/static_scene.h"
#include "iplan/framework/node.h"
#include "test_node.h"
#include "test_paths.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using SI = const dds::SampleInfo&;
const std::string kConfig = std::string(IPLAN_SOURCE_DIR) + "/config";

std::string List(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + std::to_string(v[i]);
  return s + "]";
}
std::string List(const Eigen::Vector3d& v) { return List(std::vector<double>{v.x(), v.y(), v.z()}); }

collision::RobotModel Panda() { return collision::LoadRobotModelFromYaml(kConfig + "/robots/panda.yaml"); }

struct Cell {
  explicit Cell(const std::string& tag, int domain) : domain(domain) {
    dir = std::filesystem::temp_directory_path() / ("iplan-" + tag + "-" + std::to_string(getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~Cell() {
    for (auto& [name, p] : procs) p->Signal(SIGTERM);
    for (auto& [name, p] : procs) p->Wait(10s);
    if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
    else std::cout << "service logs kept in " << dir.string() << "\n";
  }
  void Start(const std::string& exe, const std::string& cfg, std::vector<std::string> extra) {
    std::vector<std::string> argv = {BinPath(exe), "--config", kConfig + "/" + cfg, "--dds", "cyclonedds", "--domain",
                                     std::to_string(domain)};
    argv.insert(argv.end(), extra.begin(), extra.end());
    procs[exe] = std::make_unique<Process>(argv, std::map<std::string, std::string>{}, false, (dir / exe).string());
  }
  // Every service exits 0 on SIGTERM.
  void Stop() {
    for (auto& [name, p] : procs) p->Signal(SIGTERM);
    for (auto& [name, p] : procs) EXPECT_EQ(p->Wait(10s), 0) << name << ":\n" << p->Stderr();
    procs.clear();
  }
  int domain;
  std::filesystem::path dir;
  std::map<std::string, std::unique_ptr<Process>> procs;
};

// The depth path's perception: the simulated camera (10 Hz, the shipped rate) and the person's truth.
std::vector<std::string> DepthPerception(std::vector<std::string> more) {
  std::vector<std::string> a = {"--set", "perception.provider=synthetic", "--set", "perception.publish_truth=true", "--set",
                                "perception.depth.provider=simulated"};
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

// ---------------------------------------------------------------- 1. person

const std::vector<std::string> kRobotJoints = {"panda_joint1", "panda_joint2", "panda_joint3", "panda_joint4",
                                               "panda_joint5", "panda_joint6", "panda_joint7"};
const std::vector<double> kReady = {0, -0.785, 0, -2.356, 0, 1.571, 0.785};
const std::vector<double> kReach = {0, 0.3, 0, -1.5, 0, 1.9, 0.785};
constexpr double kRobotDelay = 0.5, kRobotMove = 2.5;  // s: the arm waits, then reaches out (the person's hand gets there at 3 s)
std::vector<double> PlannedAt(double t) {
  const double s = std::clamp((t - kRobotDelay) / kRobotMove, 0.0, 1.0), u = 0.5 - 0.5 * std::cos(M_PI * s);
  std::vector<double> q(7);
  for (std::size_t j = 0; j < 7; ++j) q[j] = (1 - u) * kReady[j] + u * kReach[j];
  return q;
}
msg::JointTrajectory Reaching(const msg::Time& start) {
  msg::JointTrajectory t;
  t.header.stamp = start;
  t.joint_names = kRobotJoints;
  for (int i = 0; i <= 100; ++i) {
    msg::JointTrajectoryPoint pt;
    pt.positions = PlannedAt(0.1 * i);
    pt.time_from_start = msg::DurationFromSeconds(0.1 * i);
    t.points.push_back(pt);
  }
  return t;
}

// Robot spheres at q against body spheres: smallest surface distance, m.
double Distance(const collision::RobotModel& robot, const std::vector<double>& q, const std::vector<Eigen::Vector3d>& c,
                const std::vector<double>& r) {
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, Eigen::Map<const Eigen::VectorXd>(q.data(), 7), &d);
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index k = 0; k < d.p_WS.cols(); ++k)
    for (std::size_t i = 0; i < c.size(); ++i)
      best = std::min(best, (d.p_WS.col(k) - c[i]).norm() - robot.spheres[static_cast<std::size_t>(k)].radius - r[i]);
  return best;
}

TEST(DepthChain, APersonSeenOnlyByTheDepthCameraStopsTheRobotBeforeContact) {
  const collision::RobotModel robot = Panda();
  const collision::HumanBodyModel body(collision::LoadHumanBodyParams(kConfig + "/humans/upper_body.yaml"));
  const std::vector<double> radii = body.Radii();
  // The person's right hand reaches 8 cm beyond the arm's hand at kReach (away from the base), so the arm going on
  // would run into it.
  collision::RobotData d(robot);
  collision::CalcForwardKinematics(robot, Eigen::Map<const Eigen::VectorXd>(kReach.data(), 7), &d);
  Eigen::Vector3d hand = d.X_WL[static_cast<std::size_t>(robot.FindLink("panda_hand"))].translation();
  const Eigen::Vector3d target = hand + 0.08 * Eigen::Vector3d(hand.x(), hand.y(), 0).normalized();

  Cell cell("depth-person", UniqueDomain(97));
  TestNode sc("scripted_cell", dds::Vendor::kCyclone, cell.domain);
  framework::Node& node = *sc.node;
  auto& traj = node.Advertise(framework::topics::RobotTrajectory());
  auto& cmd = node.Advertise(framework::topics::TaskCommand());
  Clock::time_point t0{};
  auto since = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  struct State { double t; std::vector<double> q, qd; std::vector<Eigen::Vector3d> body; };
  struct Truth { double t; std::vector<Eigen::Vector3d> centres; };
  struct Risk { double t; msg::CollisionRisk r; };
  std::vector<State> states;
  std::vector<Truth> truths;
  std::vector<Risk> risks;
  int point_sets = 0, skeletons = 0;
  framework::SubscribeOptions any{false};
  node.Subscribe(framework::topics::HumanTruth(), std::function<void(const msg::HumanSkeleton&, SI)>([&](const msg::HumanSkeleton& m, SI) {
                   Eigen::Matrix3Xd J(3, body.num_joints());
                   for (int j = 0; j < body.num_joints(); ++j)
                     for (const auto& h : m.joints)
                       if (h.name == body.params().joints[static_cast<std::size_t>(j)]) J.col(j) << h.position.x, h.position.y, h.position.z;
                   std::vector<Eigen::Vector3d> c;
                   for (int k = 0; k < body.num_spheres(); ++k) c.push_back(body.SphereCentre(k, J));
                   truths.push_back({since(), c});
                 }), any);
  node.Subscribe(framework::topics::JointStates(), std::function<void(const msg::JointState&, SI)>([&](const msg::JointState& m, SI) {
                   if (t0 != Clock::time_point{} && !truths.empty()) states.push_back({since(), m.position, m.velocity, truths.back().centres});
                 }), any);
  node.Subscribe(framework::topics::CollisionRisk(), std::function<void(const msg::CollisionRisk& r, SI)>([&](const msg::CollisionRisk& r, SI) {
                   risks.push_back({since(), r});
                 }), any);
  node.Subscribe(framework::topics::HumanPoints(), std::function<void(const msg::HumanPoints&, SI)>([&](const msg::HumanPoints&, SI) {
                   ++point_sets;
                 }), any);
  node.Subscribe(framework::topics::HumanSkeleton(), std::function<void(const msg::HumanSkeleton&, SI)>([&](const msg::HumanSkeleton&, SI) {
                   ++skeletons;
                 }), any);

  const std::string entitled = "node.entitled_writers./iplan/robot/trajectory=[scripted_cell]";
  cell.Start("iplan-robot-sim", "robot_sim.yaml", {"--set", "robot_sim.permits.monitors=[iplan-collision_risk]", "--set", entitled});
  cell.Start("iplan-collision-risk", "collision_risk.yaml", {"--set", entitled});
  cell.Start("iplan-perception", "perception.yaml",
             DepthPerception({"--set", "perception.publish_skeleton=false", "--set", "node.entitled_writers./iplan/task/command=[scripted_cell]",
                              "--set", "perception.synthetic.start=episodes", "--set", "perception.synthetic.variation=0", "--set",
                              "perception.synthetic.actions.reach_parts.target=" + List(target), "--set",
                              "perception.synthetic.actions.reach_parts.period=6.0", "--set", "perception.synthetic.script=[reach_parts]",
                              "--set", "perception.synthetic.durations=[6.0]"}));
  cell.Start("iplan-cloud", "cloud.yaml", {});
  // Up: the person's points reach collision risk, which lets the arm at rest go (OK).
  const auto up = Clock::now() + 40s;
  auto ok_now = [&] { return !risks.empty() && risks.back().r.verdict == msg::CollisionRisk::OK && point_sets >= 10; };
  while (Clock::now() < up && (!ok_now() || traj.MatchedReaders() < 2 || cmd.MatchedReaders() == 0)) node.SpinOnce(10ms);
  ASSERT_TRUE(ok_now()) << point_sets << " human point sets; last verdict "
                        << (risks.empty() ? std::string("none") : risks.back().r.reason) << "\n"
                        << cell.procs["iplan-cloud"]->Stderr() << cell.procs["iplan-collision-risk"]->Stderr();
  // The episode starts: the person reaches (3 s out, 3 s back), the arm reaches out from 0.5 s to 3 s.
  msg::TaskCommand c;
  c.header.stamp = msg::Now();
  c.command = msg::TaskCommand::START;
  c.episode = 1;
  c.task_id = 1;
  c.task_name = "reach";
  t0 = Clock::now();
  states.clear();
  risks.clear();
  truths.erase(truths.begin(), truths.end() - 1);
  truths.back().t = 0;
  cmd.Write(c);
  traj.Write(Reaching(msg::Now()));
  while (since() < 7.0) node.SpinOnce(5ms);
  cell.Stop();

  EXPECT_EQ(skeletons, 0) << "perception published skeletons";
  ASSERT_GT(states.size(), 100u);
  ASSERT_GT(truths.size(), 100u);
  // Without a stop the arm would run into the reaching hand: the planned arm against the true body at the same time.
  double unstopped = std::numeric_limits<double>::infinity();
  for (const Truth& tr : truths) unstopped = std::min(unstopped, Distance(robot, PlannedAt(tr.t), tr.centres, radii));
  EXPECT_LT(unstopped, -0.02);
  const Risk* stop = nullptr;
  for (const Risk& r : risks)
    if (r.r.verdict == msg::CollisionRisk::PROTECTIVE_STOP && r.r.reason.find("/ points)") != std::string::npos) {
      stop = &r;
      break;
    }
  ASSERT_NE(stop, nullptr) << "never stopped for the points; last: " << (risks.empty() ? "" : risks.back().r.reason);
  double moved = 0, closest = std::numeric_limits<double>::infinity(), late_speed = 0;
  for (const State& s : states) {
    if (s.t < stop->t) moved = std::max(moved, std::abs(s.qd[1]));
    if (s.t > stop->t + 0.6)
      for (double v : s.qd) late_speed = std::max(late_speed, std::abs(v));
    closest = std::min(closest, Distance(robot, s.q, s.body, radii));
  }
  std::cout << "unstopped arm vs true body: " << unstopped << " m; first stop for the points at +" << stop->t
            << " s: separation " << stop->r.min_separation << " m, S_p " << stop->r.protective_separation << " m: " << stop->r.reason
            << "\njoint 2 speed before the stop " << moved << " rad/s; closest executed arm vs true body " << closest
            << " m; joint speed from 0.6 s after the stop " << late_speed << " rad/s\n";
  EXPECT_GT(moved, 0.1) << "the arm never moved: the stop proves nothing";
  EXPECT_GT(closest, 0.0) << "contact with the true body";
  EXPECT_LT(late_speed, 1e-6) << "not at rest after the stop";
}

}  // namespace
}  // namespace iplan::testing

// The done-when test of issue 19's ROS 2 drop-in: a ROS 2-style robot stack
// written from ROS 2's message definitions (its own IDL in rosidl's DDS IDL
// style, tests/ros2_client/, not idl/), with ROS 2's default QoS, in its own
// process, is the robot of the cell: it publishes /joint_states as a
// joint_state_broadcaster would, and iplan-trajopt, remapped to
// /arm_controller/joint_trajectory as a joint_trajectory_controller listens,
// with zero stamps ("start on receipt"), sends it trajectories that hold
// the robot where the stack says it is, at least 1 s long, with velocities.
// iplan-robot-sim (its joint states remapped to /sim/joint_states, which
// the stack reads with default QoS) publishes world -> base on /tf_static,
// which the stack reads as tf2's static listener (the Fast DDS one through
// DynamicTypes: fastddsgen refuses rosidl's geometry_msgs IDL).
// The Cyclone stack's types carry XTypes type information with rosidl's
// member names (header_): iplan sends none, so they match. All four vendor
// pairings.
#include <sstream>

#include <gtest/gtest.h>

#include "cell_harness.h"

namespace iplan::testing {
namespace {

using namespace std::chrono_literals;

struct Pairing {
  std::string cell;
  std::string client;
};
void PrintTo(const Pairing& p, std::ostream* os) { *os << "cell " << p.cell << ", client " << p.client; }

const std::vector<double> kPositions = {0.1, -0.4, 0.05, -2.1, 0.0, 1.6, 0.7};  // rad, within the Panda's limits

// key=value fields of one report line.
std::map<std::string, std::string> Fields(const std::string& line) {
  std::map<std::string, std::string> f;
  std::istringstream in(line);
  std::string tok;
  while (in >> tok) {
    const auto eq = tok.find('=');
    if (eq != std::string::npos) f[tok.substr(0, eq)] = tok.substr(eq + 1);
  }
  return f;
}

std::vector<double> Numbers(const std::string& csv) {
  std::vector<double> v;
  std::istringstream in(csv);
  std::string x;
  while (std::getline(in, x, ',')) v.push_back(std::stod(x));
  return v;
}

class Ros2Client : public ::testing::TestWithParam<Pairing> {};

TEST_P(Ros2Client, ExchangesJointStatesTrajectoriesAndStaticTf) {
  const Pairing p = GetParam();
  CellHarness cell("ros2-client", dds::ParseVendor(p.cell), static_cast<int>(p.cell.size() * 5 + p.client.size()), "",
                   /*with_intent=*/false);
  ASSERT_TRUE(cell.ready());
  const std::string d = std::to_string(cell.domain());
  cell.Start("trajopt", {"--remap", "/iplan/robot/trajectory:=/arm_controller/joint_trajectory", "--set",
                         "trajopt.output.zero_stamp=true"});
  cell.Start("robot_sim", {"-r", "joint_states:=/sim/joint_states"});
  // The stack reads the shipped loopback profile the way any DDS
  // application does: the vendor's own environment variable.
  const std::string dds_dir = std::string(IPLAN_SOURCE_DIR) + "/config/dds/";
  std::map<std::string, std::string> env;
  if (p.client == "cyclonedds") {
    env["CYCLONEDDS_URI"] = "file://" + dds_dir + "cyclonedds-loopback.xml";
  } else {
    env["FASTRTPS_DEFAULT_PROFILES_FILE"] = dds_dir + "fastdds-loopback.xml";
  }
  const std::string binary = p.client == "cyclonedds" ? "ros2_client_cyclone" : "ros2_client_fastdds";
  std::vector<std::string> argv = {TestBinPath(binary), "--domain", d, "--trajectories", "5",
                                   "--timeout", "60", "--read-joint-states", "/sim/joint_states", "--positions"};
  for (double x : kPositions) argv.push_back(std::to_string(x));
  Process client(argv, env);
  const auto rc = client.Wait(90s);
  const std::string out = client.Stdout();
  ASSERT_TRUE(rc.has_value()) << "the ROS 2-style client did not finish\n" << out << client.Stderr();
  EXPECT_EQ(*rc, 0) << out << client.Stderr() << "\ntrajopt:\n" << cell.Logs("trajopt");

  int trajectories = 0, transforms = 0, states = 0;
  std::istringstream lines(out);
  std::string line;
  while (std::getline(lines, line)) {
    auto f = Fields(line);
    if (line.rfind("trajectory ", 0) == 0) {
      ++trajectories;
      EXPECT_EQ(f["stamp"], "0.000000000") << line;  // start on receipt
      EXPECT_EQ(f["joints"], "panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,panda_joint6,panda_joint7");
      // A hold where the stack says the robot is: trajopt read its joint states.
      const std::vector<double> first = Numbers(f["first"]), last = Numbers(f["last"]);
      ASSERT_EQ(first.size(), kPositions.size()) << line;
      ASSERT_EQ(last.size(), kPositions.size()) << line;
      for (std::size_t i = 0; i < kPositions.size(); ++i) {
        EXPECT_NEAR(first[i], kPositions[i], 1e-5) << line;
        EXPECT_NEAR(last[i], kPositions[i], 1e-5) << line;
      }
      EXPECT_GE(std::stod(f["duration"]), 0.9) << line;  // min_duration 1.0 s, less the part already past
      EXPECT_GT(std::stod(f["first_time"]), 0.0) << line;
      EXPECT_EQ(f["velocities"], f["points"]) << line;
    } else if (line.rfind("joint_state ", 0) == 0) {
      // The simulator's joint states, read with ROS 2's default QoS and types.
      ++states;
      EXPECT_EQ(f["names"], "panda_joint1,panda_joint2,panda_joint3,panda_joint4,panda_joint5,panda_joint6,panda_joint7");
      EXPECT_EQ(Numbers(f["positions"]).size(), 7u) << line;
    } else if (line.rfind("tf ", 0) == 0) {
      ++transforms;
      EXPECT_EQ(f["parent"], "world");
      EXPECT_EQ(f["child"], "panda_link0");
      EXPECT_EQ(f["translation"], "0,0,0");
      EXPECT_EQ(f["qw"], "1");
    }
  }
  EXPECT_EQ(trajectories, 5) << out;
  EXPECT_EQ(states, 3) << out;
  EXPECT_GE(transforms, 1) << out;
  std::cout << "client (" << p.client << ") <-> cell (" << p.cell << "): " << trajectories << " trajectories, "
            << transforms << " static transforms, " << states << " joint states read\n";
  cell.Stop();
}

INSTANTIATE_TEST_SUITE_P(AllPairings, Ros2Client,
                         ::testing::Values(Pairing{"cyclonedds", "cyclonedds"}, Pairing{"fastdds", "fastdds"},
                                           Pairing{"fastdds", "cyclonedds"}, Pairing{"cyclonedds", "fastdds"}),
                         [](const auto& info) { return "cell_" + info.param.cell + "_client_" + info.param.client; });

}  // namespace
}  // namespace iplan::testing

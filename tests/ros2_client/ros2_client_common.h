// What both ROS 2-style clients (Cyclone C API, Fast DDS C++ API) share: the
// command line, ROS 2's default QoS in words, and the report lines the test
// reads. No iplan headers: the clients know only their own IDL
// (ros2_interfaces.idl) and the vendor's API, as a third-party ROS 2 stack.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace ros2_client {

struct Options {
  int domain = 0;
  std::string joint_states_topic = "/joint_states";
  std::string trajectory_topic = "/arm_controller/joint_trajectory";
  std::string tf_static_topic = "/tf_static";
  /// Joint states of another robot to read (default QoS), e.g. the cell's
  /// simulator; empty: none.
  std::string read_joint_states_topic;
  std::vector<double> positions = {0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.8};  ///< rad, published as the robot's state
  double rate = 100;      ///< Hz of joint states
  double timeout = 30;    ///< s
  int trajectories = 5;   ///< stop after this many trajectories (and one /tf_static, 3 joint states read)
};

inline int Parse(int argc, char** argv, const char* what, Options* o) {
  CLI::App app{std::string("A ROS 2-style robot stack (") + what +
               "): publishes sensor_msgs/JointState on --joint-states with ROS 2's default QoS "
               "(reliable, volatile, keep last 10, infinite deadline and lease), subscribes to "
               "trajectory_msgs/JointTrajectory on --trajectory with the same QoS, and to "
               "tf2_msgs/TFMessage on --tf-static as tf2's static listener (transient local). "
               "Types from its own ROS 2 IDL. Prints one line per trajectory and transform."};
  app.add_option("--domain", o->domain, "DDS domain id");
  app.add_option("--joint-states", o->joint_states_topic, "ROS topic of the joint states")->capture_default_str();
  app.add_option("--trajectory", o->trajectory_topic, "ROS topic of the trajectories")->capture_default_str();
  app.add_option("--tf-static", o->tf_static_topic, "ROS topic of the static transforms")->capture_default_str();
  app.add_option("--read-joint-states", o->read_joint_states_topic,
                 "also subscribe to joint states on this ROS topic (default QoS) and report them");
  app.add_option("--positions", o->positions, "joint positions to report, rad")->expected(1, 64);
  app.add_option("--rate", o->rate, "joint states per second")->check(CLI::Range(1.0, 1000.0));
  app.add_option("--timeout", o->timeout, "give up after this many seconds")->check(CLI::Range(0.1, 600.0));
  app.add_option("--trajectories", o->trajectories, "stop after this many trajectories")->check(CLI::Range(1, 100000));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return -1;
}

/// The robot's joint names, as a Panda's ros2_control hardware names them.
inline std::vector<std::string> JointNames(std::size_t n) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < n; ++i) names.push_back("panda_joint" + std::to_string(i + 1));
  return names;
}

inline std::string Wire(const std::string& ros) { return "rt" + (ros.empty() || ros[0] != '/' ? "/" + ros : ros); }

inline void Now(int32_t* sec, uint32_t* nanosec) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                      std::chrono::system_clock::now().time_since_epoch()).count();
  *sec = static_cast<int32_t>(ns / 1000000000);
  *nanosec = static_cast<uint32_t>(ns % 1000000000);
}

inline std::string Join(const std::vector<double>& v) {
  std::string s;
  char buf[32];
  for (double x : v) {
    std::snprintf(buf, sizeof(buf), "%.6g", x);
    s += (s.empty() ? "" : ",") + std::string(buf);
  }
  return s;
}

inline std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

/// "trajectory stamp=S.N points=P duration=D joints=a,b first=x,y last=x,y velocities=V"
inline void ReportTrajectory(int32_t sec, uint32_t nanosec, const std::vector<std::string>& joints,
                             const std::vector<std::vector<double>>& positions, const std::vector<double>& times,
                             std::size_t points_with_velocities) {
  std::printf("trajectory stamp=%d.%09u points=%zu duration=%.6f joints=%s first=%s last=%s velocities=%zu first_time=%.6f\n",
              sec, nanosec, positions.size(), times.empty() ? 0.0 : times.back(), Join(joints).c_str(),
              positions.empty() ? "" : Join(positions.front()).c_str(),
              positions.empty() ? "" : Join(positions.back()).c_str(), points_with_velocities,
              times.empty() ? 0.0 : times.front());
  std::fflush(stdout);
}

/// "joint_state names=a,b positions=x,y" (the first few only: see the caller).
inline void ReportJointState(const std::vector<std::string>& names, const std::vector<double>& positions) {
  std::printf("joint_state names=%s positions=%s\n", Join(names).c_str(), Join(positions).c_str());
  std::fflush(stdout);
}

inline void ReportTransform(const std::string& parent, const std::string& child, double tx, double ty, double tz,
                            double qw) {
  std::printf("tf parent=%s child=%s translation=%.6g,%.6g,%.6g qw=%.6g\n", parent.c_str(), child.c_str(), tx, ty, tz, qw);
  std::fflush(stdout);
}

}  // namespace ros2_client

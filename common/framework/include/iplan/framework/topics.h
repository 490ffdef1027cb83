// The topics of an iplan cell: name, type and QoS of each, in one place so
// that both sides of every topic agree (docs/topics.md is the prose version).
// Names follow ROS 2: the "rt/" prefix on the wire; ROS 2 tools see them as
// /joint_states, /iplan/human/skeleton, ...
#pragma once

#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "iplan/dds/qos.h"
#include "iplan/msg/types.h"

namespace iplan::framework {

/// A topic of type T with the QoS both its writers and readers use.
template <class T>
struct Topic {
  std::string name;  ///< DDS topic name, e.g. "rt/iplan/human/skeleton"
  dds::QosProfile qos;
  /// Participant names entitled to write it (readers ignore everyone else;
  /// `node.entitled_writers` overrides); empty: any writer (sensor data
  /// from any provider, diagnostics).
  std::vector<std::string> writers = {};
  /// Positions in the cell frame: header.frame_id must name it.
  bool in_cell_frame = false;
};

/// Untyped description for tools and docs.
struct TopicDescription {
  std::string name;
  std::string type;  ///< DDS type name
  dds::QosProfile qos;
  std::string description;
};

namespace topics {

/// Tracked human skeletons from perception (30 Hz nominal).
Topic<msg::HumanSkeleton> HumanSkeleton();
/// The simulated person's true pose (simulation only; contact counting).
Topic<msg::HumanSkeleton> HumanTruth();
/// Depth camera points (30 Hz nominal) from any provider: perception's
/// simulated camera or PCD replay, or a ROS 2 camera driver. Frame: the
/// sensor's (header.frame_id); the cloud stage knows its pose in the cell.
Topic<msg::PointCloud2> DepthPoints();
/// The same camera's depth image (16UC1 in mm or 32FC1 in m, the sensor's
/// frame): a quarter of a cloud's bytes, so the camera can run at 30 Hz on
/// loopback; the cloud service unprojects it with the camera's intrinsics
/// (DepthCameraInfo).
Topic<msg::Image> DepthImage();
/// The depth camera's calibration (pinhole intrinsics, pixels), published
/// beside each depth image with its stamp, as ROS 2 camera drivers do: what
/// the cloud service unprojects DepthImage with.
Topic<msg::CameraInfo> DepthCameraInfo();
/// Static unknown obstacles (boxes, cell frame) the cloud stage found.
Topic<msg::ObstacleArray> Obstacles();
/// Points of moving objects (people) the cloud stage found, each with the
/// sensor's noise covariance (cell frame).
Topic<msg::HumanPoints> HumanPoints();
/// p(action | motion) from intent, one per skeleton.
Topic<msg::ActionBelief> ActionBelief();
/// Predicted human motion mixture from intent, one per skeleton.
Topic<msg::HumanPrediction> HumanPrediction();
/// Robot joint state from the robot (or simulator).
Topic<msg::JointState> JointStates();
/// The robot trajectory being executed (latched; replaced every cycle).
Topic<msg::JointTrajectory> RobotTrajectory();
/// Task commands from the supervisor to the trajectory optimiser.
Topic<msg::TaskCommand> TaskCommand();
/// Task outcomes from the trajectory optimiser.
Topic<msg::TaskOutcome> TaskOutcome();
/// One status per replanning cycle (with the end-to-end latency).
Topic<msg::PlanStatus> PlanStatus();
/// Collision risk of the executing trajectory.
Topic<msg::CollisionRisk> CollisionRisk();
/// Permission to move from one safety monitor, re-published every period.
/// Each monitor has a topic of its own: "rt/iplan/safety/permit/<service>"
/// for the monitor whose participant is "iplan-<service>" (any other name:
/// the whole name, with '-' and '.' as '_'), entitled to that participant
/// alone. With DDS Security only that monitor's enclave is granted to
/// publish it (enclaves.h), so the topic a permit arrives on is its
/// authenticated origin. Volatile: a late joiner must wait for a fresh
/// permit, never replay an old one. Throws std::invalid_argument when
/// `monitor` gives no valid topic name.
Topic<msg::SafetyPermit> SafetyPermit(const std::string& monitor);
/// The shipped monitors' permit topics: SafetyPermit("iplan-supervisor"),
/// SafetyPermit("iplan-collision_risk").
Topic<msg::SafetyPermit> SupervisorPermit();
Topic<msg::SafetyPermit> CollisionRiskPermit();
/// Per-service diagnostics (ROS 2 /diagnostics).
Topic<msg::DiagnosticArray> Diagnostics();

/// Static transforms (ROS 2 /tf_static, transient local like tf2's static
/// broadcaster): `world` -> the robot's base, from the robot simulator.
Topic<msg::TFMessage> TfStatic();

/// Every topic above, in that order.
std::vector<TopicDescription> All();

// Remapping, as ROS 2's `--remap FROM:=TO`: every function above returns the
// remapped name once SetRemappings() has been called (RunService does, from
// `--remap` and the `node.remap` configuration, before the service
// configures). Names are ROS names ("/joint_states"; "joint_states" is read
// as "/joint_states"); the wire name is "rt" + the ROS name.

/// Parses "FROM:=TO" into ROS names. False with the reason in `error`.
bool ParseRemapRule(const std::string& rule, std::string* from, std::string* to, std::string* error);
/// Replaces the remappings (FROM -> TO, ROS names). Empty when accepted;
/// else the reason, and nothing changes: a FROM that is not a catalogue
/// topic, a TO that is not a valid ROS 2 topic name, or two topics on one name.
std::string SetRemappings(const std::map<std::string, std::string>& from_to);
/// The catalogue name (wire, "rt/...") a possibly remapped wire name came
/// from; the name itself when it is not a remapped one.
std::string CatalogueName(const std::string& dds_name);

}  // namespace topics
}  // namespace iplan::framework

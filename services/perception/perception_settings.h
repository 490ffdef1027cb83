// The keys of section `perception` (config/perception.yaml), declared once:
// read by the perception service, and by `iplan demo`, `iplan eval`,
// `iplan cell-check` and the depth benchmark, which need the same person;
// listed by `iplan config defaults perception`. Every range is checked in
// Validate(), so a file is refused before anything starts.
//
// Frames and units: positions in the world frame W (the robot's base, x
// towards the person, z up from the table top), m; angles rad; times s.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "services/perception/core/depth_camera.h"
#include "services/perception/core/skeleton_replay.h"
#include "services/perception/core/synthetic_person.h"
#include "iplan/cloud/camera.h"
#include "iplan/cloud/noise.h"
#include "iplan/core/name_value.h"
#include "iplan/core/params.h"

namespace iplan::perception {

/// How the synthetic person's script is started.
enum class ScriptStart {
  kLoop,      ///< at start-up, repeated for ever
  kEpisodes,  ///< with each task-planning episode (the first task command of an episode)
};

/// One action of perception.synthetic.actions (its name is the key).
struct ActionSettings {
  std::string motion = "reach";
  std::string hand = "right";
  std::optional<std::array<double, 3>> target;
  double period = ActionMotion{}.period;
  double amplitude = ActionMotion{}.amplitude;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP_REQUIRED(motion, "reach (one hand to target and back), work (both hands around target) or rest"));
    a->Visit(IPLAN_NVP(hand, "left or right: the hand that reaches"));
    a->Visit(IPLAN_NVP(target, "m, W; reach: the hand's target, work: the centre between the hands (required for both)"));
    a->Visit(IPLAN_NVP(period, "s; one reach out and back, one work circle, one sway; > 0"));
    a->Visit(IPLAN_NVP(amplitude, "m; work: circle radius, rest: sway; >= 0"));
  }
  std::string Validate() const;
  /// The core's action named `name`.
  ActionMotion ToMotion(const std::string& name) const;
};

/// One further person of perception.synthetic.more_people: absent keys are
/// the first person's (seed: the first person's + the person's index).
struct MorePersonSettings {
  std::optional<std::array<double, 3>> torso;
  std::optional<double> facing_yaw;
  std::optional<std::uint64_t> seed;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(torso, "m, W; the torso joint"));
    a->Visit(IPLAN_NVP(facing_yaw, "rad; the direction the person faces"));
    a->Visit(IPLAN_NVP(seed, "noise and variation seed"));
  }
  std::string Validate() const { return ""; }
};

/// perception.synthetic: the simulated person (core/synthetic_person.h).
struct SyntheticSettings {
  std::array<double, 3> torso = {1.0, 0.0, 1.05};
  double facing_yaw = SyntheticPersonParams{}.facing_yaw;
  double noise_stddev = SyntheticPersonParams{}.noise_stddev;
  double variation = SyntheticPersonParams{}.variation;
  double transition = SyntheticPersonParams{}.transition;
  std::array<double, 3> rest_hand = {0.25, 0.20, -0.25};
  std::uint64_t seed = SyntheticPersonParams{}.seed;
  std::string start = "loop";
  /// Default: one right-hand reach (the core's default action).
  core::Named<ActionSettings> actions = {{"reach", ActionSettings{"reach", "right", std::array<double, 3>{0.62, 0.10, 0.95}}}};
  std::vector<std::string> script;
  std::vector<double> durations;
  std::vector<MorePersonSettings> more_people;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(torso, "m, W; the torso joint"));
    a->Visit(IPLAN_NVP(facing_yaw, "rad; the direction the person faces (pi: towards -x, the robot)"));
    a->Visit(IPLAN_NVP(noise_stddev, "m per coordinate, sensor noise, >= 0"));
    a->Visit(IPLAN_NVP(variation, "m, std dev of the target offset between repetitions, >= 0"));
    a->Visit(IPLAN_NVP(transition, "s, blend of the hands from one action into the next, >= 0"));
    a->Visit(IPLAN_NVP(rest_hand, "m, the left hand at rest from the torso, person frame (x forward, y left); right mirrored"));
    a->Visit(IPLAN_NVP(seed, "noise and variation seed"));
    a->Visit(IPLAN_NVP(start, "episodes: the script starts with each task-planning episode; loop: at start-up, for ever"));
    a->Visit(IPLAN_NVP(actions, "name: motion; the actions the person can do"));
    a->Visit(IPLAN_NVP(script, "action names, in order (empty: the first action for ever)"));
    a->Visit(IPLAN_NVP(durations, "s per script step, one each; after the last the person idles until the next episode"));
    a->Visit(IPLAN_NVP(more_people, "further persons, bodies 2, 3, ...; the same actions and script"));
  }
  std::string Validate() const;
  ScriptStart Start() const { return start == "episodes" ? ScriptStart::kEpisodes : ScriptStart::kLoop; }
  /// The first person (body 1).
  SyntheticPersonParams Person() const;
  /// The further persons (bodies 2, 3, ...).
  std::vector<SyntheticPersonParams> MorePeople() const;
};

/// perception.replay.transform: the recording's sensor frame in W, as a
/// translation and a yaw or as a matrix.
struct ReplayTransformSettings {
  std::optional<std::array<double, 3>> translation;
  std::optional<double> yaw;
  std::optional<std::vector<double>> matrix;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(translation, "m; default [0, 0, 0]"));
    a->Visit(IPLAN_NVP(yaw, "rad about world z; default 0"));
    a->Visit(IPLAN_NVP(matrix, "16 numbers, a 4x4 rigid transform, row-major; instead of translation and yaw"));
  }
  std::string Validate() const;
  Eigen::Isometry3d Pose() const;  ///< X_WS; valid settings only
};

/// perception.replay: recorded sequences of a skeleton CSV.
struct ReplaySettings {
  std::string file;
  std::vector<std::string> sequences;
  std::vector<std::string> subjects;
  bool loop = SkeletonReplayParams{}.loop;
  double rate = SkeletonReplayParams{}.rate;
  double pause = SkeletonReplayParams{}.pause;
  double start_delay = SkeletonReplayParams{}.start_delay;
  std::map<std::string, std::string> joint_map;
  ReplayTransformSettings transform;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(file, "CSV in the shared layout, relative to the configuration file; required with provider replay"));
    a->Visit(IPLAN_NVP(sequences, "sequence ids to play, in file order; empty: all"));
    a->Visit(IPLAN_NVP(subjects, "only these subjects' sequences; empty: all"));
    a->Visit(IPLAN_NVP(loop, "start again after the last sequence (each play is a new body_id)"));
    a->Visit(IPLAN_NVP(rate, "playback speed factor (2: twice as fast), > 0"));
    a->Visit(IPLAN_NVP(pause, "s between two sequences, > 0"));
    a->Visit(IPLAN_NVP(start_delay, "s before the first frame, >= 0"));
    a->Visit(IPLAN_NVP(joint_map, "CSV joint name: published name; joints not listed keep their name"));
    a->Visit(IPLAN_NVP(transform, "pose of the recording's sensor frame in W"));
  }
  std::string Validate() const;
  /// The core's parameters, `file` resolved by the caller.
  SkeletonReplayParams ToParams(const std::string& resolved_file) const;
};

/// perception.depth.simulated: the rendered Kinect-class camera.
struct SimulatedDepthSettings {
  cloud::CameraLookAt camera;
  cloud::CameraIntrinsics intrinsics;
  cloud::DepthNoiseParams noise;
  bool add_noise = DepthCameraParams{}.add_noise;
  double min_range = DepthCameraParams{}.min_range;
  double max_range = DepthCameraParams{}.max_range;
  std::uint64_t seed = DepthCameraParams{}.seed;
  std::vector<std::string> scenes = {"scenes/cell.yaml"};
  std::vector<std::string> added_scenes;
  double added_after = 0.0;
  std::string human_body = "humans/upper_body.yaml";
  double human_after = 0.0;
  std::string robot = "robots/panda.yaml";

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(camera, "pose of the optical frame in W (keep equal to cloud.yaml's camera)"));
    a->Visit(IPLAN_NVP(intrinsics, "pixels"));
    a->Visit(IPLAN_NVP(noise, "the depth noise model (Nguyen et al. 2012)"));
    a->Visit(IPLAN_NVP(add_noise, "add the noise to the rendered depth"));
    a->Visit(IPLAN_NVP(min_range, "m; nearer: no return, >= 0"));
    a->Visit(IPLAN_NVP(max_range, "m; farther: no return, > min_range"));
    a->Visit(IPLAN_NVP(seed, "noise seed"));
    a->Visit(IPLAN_NVP(scenes, "scene files (boxes, cylinders) to render, relative to the configuration file"));
    a->Visit(IPLAN_NVP(added_scenes, "more scene files, rendered only from added_after on"));
    a->Visit(IPLAN_NVP(added_after, "s after the service's activation, >= 0"));
    a->Visit(IPLAN_NVP(human_body, "the synthetic person's spheres at its true pose; \"\": no person"));
    a->Visit(IPLAN_NVP(human_after, "s after activation before the person is rendered, >= 0"));
    a->Visit(IPLAN_NVP(robot, "the robot's collision spheres at the latest /joint_states; \"\": no robot"));
  }
  std::string Validate() const;
  /// The camera's parameters (pose, intrinsics, noise, ranges, seed); valid settings only.
  DepthCameraParams Camera() const;
};

/// perception.depth.pcd: recorded PCD files.
struct PcdSettings {
  std::string path;
  bool loop = true;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(path, "a .pcd file or a folder of them (name order), relative to the configuration file; required with provider pcd"));
    a->Visit(IPLAN_NVP(loop, "start again after the last file"));
  }
  std::string Validate() const { return ""; }
};

/// perception.depth: the depth camera, clouds on /iplan/depth/points.
struct DepthSettings {
  std::string provider = "none";
  double rate_hz = 30;
  std::string frame_id = "depth_camera";
  std::string transport = "points";
  SimulatedDepthSettings simulated;
  PcdSettings pcd;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(provider, "none, simulated (a rendered camera) or pcd (recorded files)"));
    a->Visit(IPLAN_NVP(rate_hz, "Hz, clouds per second, in [0.1, 120]"));
    a->Visit(IPLAN_NVP(frame_id, "frame_id of the clouds (the camera's optical frame)"));
    a->Visit(IPLAN_NVP(transport, "points: PointCloud2 on /iplan/depth/points (x, y, z: 12 bytes a pixel); image: a 16UC1 depth image in mm on /iplan/depth/image (2 bytes a pixel) and its calibration on /iplan/depth/camera_info, which the cloud service unprojects it with (provider simulated only)"));
    a->Visit(IPLAN_NVP(simulated, "provider simulated"));
    a->Visit(IPLAN_NVP(pcd, "provider pcd"));
  }
  std::string Validate() const;
};

/// Section perception.
struct PerceptionSettings {
  std::string provider = "synthetic";
  double rate_hz = 30;
  std::string frame_id = "world";
  bool publish_skeleton = true;
  bool publish_truth = false;
  SyntheticSettings synthetic;
  ReplaySettings replay;
  DepthSettings depth;

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(IPLAN_NVP(provider, "synthetic (a simulated person) or replay (recorded sequences)"));
    a->Visit(IPLAN_NVP(rate_hz, "Hz, skeletons per second (synthetic; replay uses the recorded times), in [0.5, 1000]"));
    a->Visit(IPLAN_NVP(frame_id, "frame of the published positions"));
    a->Visit(IPLAN_NVP(publish_skeleton, "false: no skeletons on /iplan/human/skeleton (only the depth camera sees the person)"));
    a->Visit(IPLAN_NVP(publish_truth, "also publish the noise-free pose on /iplan/sim/human_truth (synthetic only)"));
    a->Visit(IPLAN_NVP(synthetic, "the simulated person"));
    a->Visit(IPLAN_NVP(replay, "recorded sequences"));
    a->Visit(IPLAN_NVP(depth, "the depth camera"));
  }
  /// "" when valid, else the reason, naming the key (e.g. "synthetic.torso ...").
  std::string Validate() const;
};

}  // namespace iplan::perception

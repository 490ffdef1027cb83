// Turns the cell's messages into 3D scene entities in Foxglove's published
// schema foxglove.SceneUpdate (JSON form, as @foxglove/schemas describes it):
// the robot's collision spheres and links at the current joint state (forward
// kinematics of the cell's robot model), the static scene objects, the
// person's skeleton and body spheres, the predicted future body spheres per
// action shaded by probability, the trajectory's end-effector path with ghost
// poses, and the ISO/TS 15066 separation and verdict as text.
//
// Pure code: no DDS, no sockets. Not thread-safe (one caller).
// Frames and units: every position is in the cell frame "world" (z up), m;
// colours are RGBA in [0, 1].
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "iplan/collision/human_model.h"
#include "iplan/collision/robot_model.h"
#include "iplan/collision/scene.h"
#include "iplan/msg/types.h"

namespace iplan::viewer {

/// What the viewer draws the cell from (the same files the services use).
struct CellModel {
  collision::RobotModel robot;
  collision::SceneParams scene;
  collision::HumanBodyModel body{collision::HumanBodyParams::DefaultUpperBody()};
};

/// Loads the cell model: robot (config/robots/*.yaml or a URDF), scene
/// (config/scenes/*.yaml) and body (config/humans/*.yaml).
/// @throws std::runtime_error naming the file and the problem.
CellModel LoadCellModel(const std::string& robot_file, const std::string& scene_file, const std::string& body_file);

/// Entity ids of the scene channel (one SceneUpdate per entity and update).
namespace entity {
inline constexpr const char* kStatic = "scene";
inline constexpr const char* kRobot = "robot";
inline constexpr const char* kPerson = "person";
inline constexpr const char* kPrediction = "prediction";
inline constexpr const char* kTrajectory = "trajectory";
inline constexpr const char* kSafety = "safety";
inline constexpr const char* kObstacles = "obstacles";
inline constexpr const char* kBoxes = "boxes";
inline constexpr const char* kHumanPoints = "human_points";
}  // namespace entity

/// A colour, red, green, blue and opacity in [0, 1].
struct Rgba {
  double r, g, b, a;
};

struct SceneBuilderOptions {
  /// Prediction steps drawn (evenly spread over the horizon, the last one
  /// included: 2 = half the horizon and its end); bounds the number of
  /// spheres per update. Faint overlapping spheres are what software WebGL
  /// draws slowest (docs/viewer.md, Measurements).
  int prediction_steps = 2;
  /// Actions drawn: the most probable ones.
  int prediction_actions = 3;
  /// Ghost poses drawn along a trajectory (robot spheres at evenly spread waypoints).
  int ghost_poses = 3;
  /// Obstacle points drawn at most (evenly subsampled), as cubes of this edge (m).
  int max_cloud_points = 3000;
  double cloud_point_size = 0.015;
};

class SceneBuilder {
 public:
  explicit SceneBuilder(CellModel model, SceneBuilderOptions options = {});

  /// The static objects (boxes, cylinders) as one SceneUpdate.
  nlohmann::json Static(const msg::Time& stamp) const;
  // The next four return the entity's update, kept by the builder and valid
  // until the next call for the same entity (updated in place: a steady
  // stream allocates little); nullptr (counted in rejected()) when the input
  // does not fit the model: unknown joint names, inconsistent sizes.

  /// Robot spheres and links at `js`.
  const nlohmann::json* Robot(const msg::JointState& js);
  /// Skeleton (bones as lines) and body spheres.
  const nlohmann::json* Person(const msg::HumanSkeleton& s);
  /// Predicted body spheres at a few future steps for the most probable
  /// actions; colour per action, opacity from its probability.
  const nlohmann::json* Prediction(const msg::HumanPrediction& p);
  /// End-effector path of the newly planned trajectory, the previous plan's
  /// path faded, and ghost robot poses along the new one.
  const nlohmann::json* Trajectory(const msg::JointTrajectory& t);
  /// Obstacle points (a PointCloud2 in the cell frame "world" with FLOAT32
  /// fields x, y, z, little endian) as small cubes; non-finite points are
  /// skipped.
  const nlohmann::json* Obstacles(const msg::PointCloud2& c);
  /// The cloud service's static obstacles (/iplan/obstacles) as translucent
  /// boxes, each with its pose (the cell frame "world" only).
  const nlohmann::json* Boxes(const msg::ObstacleArray& a);
  /// The cloud service's human points (/iplan/human/points, "world") as
  /// cubes of the voxel size (at most max_cloud_points, evenly subsampled):
  /// points of a tracked part in one colour, untracked ones in another; and
  /// each tracked part's velocity as a line from its points' centroid to
  /// where it is in 0.5 s.
  const nlohmann::json* HumanPoints(const msg::HumanPoints& p);
  /// Separation, S_p and verdict as text above the table, coloured by verdict.
  nlohmann::json Safety(const msg::CollisionRisk& r) const;

  /// Inputs that did not fit the model (unknown joints, wrong sizes).
  uint64_t rejected() const { return rejected_; }
  const std::string& last_rejection() const { return last_rejection_; }
  const CellModel& model() const { return model_; }

 private:
  std::optional<Eigen::VectorXd> JointVector(const std::vector<std::string>& names, const std::vector<double>& q);
  nlohmann::json& Persistent(const char* id, const msg::Time& stamp);
  void PutRobotSpheres(nlohmann::json& array, std::size_t first, const Eigen::VectorXd& q, const Rgba& color);
  Eigen::Vector3d EndEffector(const Eigen::VectorXd& q);
  void Reject(const std::string& why);

  CellModel model_;
  SceneBuilderOptions options_;
  collision::RobotData data_;
  nlohmann::json previous_path_ = nlohmann::json::array();
  std::map<std::string, nlohmann::json> updates_;  // entity id -> its last SceneUpdate
  uint64_t rejected_ = 0;
  std::string last_rejection_;
};

}  // namespace iplan::viewer
